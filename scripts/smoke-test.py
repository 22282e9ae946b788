"""A first look at an installed robodyn, run by scripts/test from the wheel in a fresh environment:
it imports, loads the bundled and an example-robot-data model, and its dynamics are consistent."""

import numpy as np

import robodyn

for name in robodyn.models():
    model = robodyn.load(name)
    q = model.random_configuration(seed=0)
    v = np.linspace(-1.0, 1.0, model.nv)
    a = np.linspace(0.5, -0.5, model.nv)
    tau = model.inverse_dynamics(q, v, a)
    # forward dynamics undoes inverse dynamics, and M from CRBA equals M from n RNEA calls
    assert np.allclose(model.forward_dynamics(q, v, tau), a, atol=1e-9), name
    assert np.allclose(model.mass_matrix(q), model.mass_matrix(q, method="rnea"), atol=1e-10), name

talos = robodyn.load("talos_full_v2.urdf", floating_base=True)
batch = talos.generalized_gravity(talos.random_configuration(n=64, seed=1))
assert batch.shape == (64, talos.nv) and np.isfinite(batch).all()
print(f"smoke test: robodyn {robodyn.__version__} from {robodyn.__file__}: bundled models and Talos ok")
