"""The `robodyn` command: every command takes a bundled name or a model file; each bad argument is
one line naming it and exit status 2, checked before any work is done; never a traceback."""

from __future__ import annotations

import io
import subprocess
import sys

import pytest
from conftest import REPOSITORY

import robodyn
from robodyn.cli import main

MODEL_FILES = {
    "urdf": REPOSITORY / "models" / "planar2.urdf",
    "mjcf": REPOSITORY / "testdata" / "mjcf" / "iiwa14_scene.xml",
    "dh": REPOSITORY / "models" / "ur5_dh.toml",
}

#: (arguments, what the one-line message names)
BAD_ARGUMENTS = [
    (["demo", "--batch", "0"], "argument --batch: expected a positive integer, got 0"),
    (["demo", "--batch", "-5"], "argument --batch: expected a positive integer, got -5"),
    (["demo", "--batch", "many"], "argument --batch: expected a positive integer, got 'many'"),
    (["demo", "no_such_robot.urdf"], "model file not found: 'no_such_robot.urdf'"),
    (["info", "robot.sdf"], "not a bundled model"),
    (["derive", "nothing"], "argument model: expected planar<n>"),
    (["derive", "missing.toml"], "model file not found: 'missing.toml'"),
    (["derive", "robot.xml"], "argument model: the symbolic layer reads URDF files and DH tables, not MJCF"),
    (["derive", "planar2", "-o", "/no/such/folder/eom.c"], "argument '-o/--output': the folder /no/such/folder does not exist"),
    (["simulate", "ur5", "--t", "-1"], "argument --t: expected a positive number, got -1"),
    (["simulate", "ur5", "--dt", "0"], "argument --dt: expected a positive number, got 0"),
    (["simulate", "ur5", "--integrator", "leapfrog"], "argument --integrator: invalid choice: 'leapfrog'"),
    (["simulate", "ur5", "--q0", "0", "1"], "argument --q0: expected 6 numbers (nq of ur5), got 2"),
    (["simulate", "ur5", "--controller", "pd", "--target", "1"], "argument --target: expected 6 numbers (nq of ur5), got 1"),
    (["simulate", "ur5", "--target", "0", "0", "0", "0", "0", "0"], "argument --target: only the pd controller takes a target"),
    (["simulate", "ur5", "--plot", "/no/such/folder/out.png"], "argument '--plot': the folder /no/such/folder does not exist"),
    (["simulate", "ur5", "--plot", "out.xyz"], "argument '--plot': expected a file ending in one of"),
    (["simulate", "ur5", "--animate", "out.avi"], "argument '--animate': expected a .gif or .mp4 file"),
    (["simulate", "ur5", "--csv", "/no/such/folder/out.csv"], "argument '--csv': the folder /no/such/folder does not exist"),
    (["simulate", "missing.urdf"], "model file not found"),
    (["frobnicate"], "argument command: invalid choice: 'frobnicate'"),
]


@pytest.mark.parametrize(("arguments", "message"), BAD_ARGUMENTS, ids=[" ".join(a) for a, _ in BAD_ARGUMENTS])
def test_a_bad_argument_is_one_line_and_exit_2(arguments, message, capsys, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    assert main(arguments) == 2
    captured = capsys.readouterr()
    lines = captured.err.strip().splitlines()
    assert len(lines) == 1 and message in lines[0], captured.err
    assert "Traceback" not in captured.err and captured.out == ""


def test_mp4_without_ffmpeg_fails_before_simulating(capsys, tmp_path, monkeypatch):
    from matplotlib import animation

    monkeypatch.setattr(animation.writers, "is_available", lambda name: False)
    assert main(["simulate", "ur5", "--t", "100", "--animate", str(tmp_path / "swing.mp4")]) == 2
    captured = capsys.readouterr()
    assert "needs ffmpeg" in captured.err and captured.out == ""


def test_plot_without_matplotlib_fails_before_simulating(capsys, tmp_path, monkeypatch):
    monkeypatch.setitem(sys.modules, "matplotlib", None)
    assert main(["simulate", "ur5", "--t", "100", "--plot", str(tmp_path / "swing.png")]) == 2
    captured = capsys.readouterr()
    assert "matplotlib" in captured.err.strip() and len(captured.err.strip().splitlines()) == 1


def test_the_installed_command_reports_errors_without_a_traceback(tmp_path):
    result = subprocess.run([sys.executable, "-m", "robodyn.cli", "demo", "--batch", "-5"], capture_output=True, text=True, cwd=tmp_path)
    assert result.returncode == 2
    assert result.stderr.strip() == "robodyn demo: argument --batch: expected a positive integer, got -5"


def test_version(capsys):
    with pytest.raises(SystemExit) as exit_status:
        main(["--version"])
    assert exit_status.value.code == 0
    assert capsys.readouterr().out.strip() == f"robodyn {robodyn.__version__}"


@pytest.mark.parametrize("kind", sorted(MODEL_FILES))
def test_every_command_takes_a_model_file(kind, capsys, tmp_path):
    path = str(MODEL_FILES[kind])
    assert main(["demo", path, "--batch", "10"]) == 0
    assert "forward_dynamics(inverse_dynamics(a)) == a: yes" in capsys.readouterr().out
    assert main(["info", path]) == 0
    assert "Joints" in capsys.readouterr().out
    assert main(["simulate", path, "--t", "0.05", "--csv", str(tmp_path / "run.csv")]) == 0
    assert (tmp_path / "run.csv").exists()


def test_info_lists_joints_bodies_frames_and_warnings(capsys):
    assert main(["info", "ur5"]) == 0
    out = capsys.readouterr().out
    assert out.startswith("ur5: nq = 6, nv = 6, 6 joints, 6 bodies, 8 frames, total mass")
    for expected in ("shoulder_pan_joint   revolute", "-6.28319 rad", "upper_arm_link", "8.393", "tool0  (wrist_3_link)", "Warnings: 0"):
        assert expected in out, expected


def test_derive_takes_a_bundled_model(capsys):
    assert main(["derive", "ur5"]) == 0
    out = capsys.readouterr().out
    assert out.startswith("ur5: tau = M(q) qdd") and "M[1,1] =" in out


def test_pd_drives_to_its_target(capsys, tmp_path):
    target = ["0.3", "-1.0", "1.0", "0.0", "0.5", "0.0"]
    out = tmp_path / "run.npz"
    assert main(["simulate", "ur5", "--t", "3", "--controller", "pd", "--target", *target, "--npz", str(out)]) == 0
    import numpy as np

    q = np.load(out)["q"]
    assert np.allclose(q[-1], [float(x) for x in target], atol=1e-3)


LIMITED_PENDULUM = """<robot name="limited">
  <link name="base"/>
  <link name="arm"><inertial><origin xyz="0 0 -1"/><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <joint name="hinge" type="revolute"><parent link="base"/><child link="arm"/><axis xyz="0 1 0"/>
    <limit lower="-0.4" upper="0.6" effort="10" velocity="10"/></joint>
  <link name="slider"><inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <joint name="slide" type="prismatic"><parent link="base"/><child link="slider"/><axis xyz="0 0 1"/>
    <limit lower="-0.1" upper="0.1" effort="10" velocity="10"/></joint>
</robot>"""


def test_limit_messages_have_units(capsys, tmp_path):
    """A pendulum swinging from 0.45 rad past its −0.4 rad limit, a slider falling past its ±0.1 m one."""
    path = tmp_path / "limited.urdf"
    path.write_text(LIMITED_PENDULUM)
    assert main(["simulate", str(path), "--t", "1", "--q0", "0.45", "0.0"]) == 0
    limits = [line for line in capsys.readouterr().out.splitlines() if line.startswith("limit:")]
    assert len(limits) == 2, limits
    assert limits[0].startswith("limit: hinge left its range") and limits[0].endswith(" rad")
    assert limits[1].startswith("limit: slide left its range") and limits[1].endswith(" m")


class Terminal(io.StringIO):
    """Standard error as a terminal, so that progress shows."""

    def isatty(self) -> bool:
        return True


def test_a_long_derivation_shows_its_progress_on_a_terminal(monkeypatch, capsys):
    import robodyn.cli as cli

    terminal = Terminal()
    monkeypatch.setattr(cli, "DERIVE_STATUS_AFTER_S", 0.0)
    monkeypatch.setattr(sys, "stderr", terminal)
    assert main(["derive", "planar3", "--rods", "--newton-euler"]) == 0
    shown = terminal.getvalue()
    assert "Euler–Lagrange equations of planar3 ... done in" in shown
    assert "Newton–Euler, and the difference ... done in" in shown


def test_writing_a_gif_shows_its_progress_on_a_terminal(monkeypatch, tmp_path):
    terminal = Terminal()
    monkeypatch.setattr(sys, "stderr", terminal)
    assert main(["simulate", "planar2", "--t", "0.2", "--dt", "0.01", "--animate", str(tmp_path / "swing.gif")]) == 0
    frames = terminal.getvalue()
    assert frames.startswith("\rwriting frames [") and frames.rstrip().endswith("100.0 %")
    assert (tmp_path / "swing.gif").read_bytes()[:6] == b"GIF89a"
