"""# Inertia tensors of a box

The TU Berlin notes, "Inertia Tensor Example": a uniform box of sides w, l, h about its corner, the
parallel-axis theorem, and its principal moments; the UR5 dynamics notes: I = R I_b Rᵀ.

    python examples/inertia_tensor.py
"""

import numpy as np
from _compare import show

from robodyn import free_body, inertia

m, w, l, h = 3.0, 0.2, 0.5, 0.3
corner = [
    [m / 3 * (l**2 + h**2), -m / 4 * w * l, -m / 4 * h * w],
    [-m / 4 * w * l, m / 3 * (w**2 + h**2), -m / 4 * h * l],
    [-m / 4 * h * w, -m / 4 * h * l, m / 3 * (l**2 + w**2)],
]
show("box about a corner", corner, inertia.solid_box(m, (w, l, h), about="corner"))
centre = np.diag([m * (l**2 + h**2) / 12, m * (w**2 + h**2) / 12, m * (w**2 + l**2) / 12])
show("ᶜI = ᴬI − m[(pᵀp) 1 − p pᵀ], p = (w, l, h)/2", centre, inertia.shift_to_com(corner, m, (w / 2, l / 2, h / 2)))
moments, axes = inertia.principal_axes(corner)
show("principal moments: eigenvalues of ᴬI", np.linalg.eigvalsh(corner), moments)
rotation = free_body.euler123_rotation([0.3, -0.2, 0.5])
show("I = R I_b Rᵀ keeps the trace", np.trace(centre), np.trace(inertia.rotate(centre, rotation)))
