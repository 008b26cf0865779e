"""Kinematics of whole arrays on seeded random machines.

Forward kinematics is judged against a separate numpy implementation of
the machine model's normative formula (machine-model.md §3: affine
rotations about lines, head chain on -L·t0 and t0, table chain undone);
inverse solutions and the control's choice are judged by forward
kinematics of what they return (tip within 1e-6 mm, direction within
1e-9 rad), never by the kernel's own inverse arithmetic.
"""

from __future__ import annotations

import math
import random
from typing import List, Tuple

import numpy as np
import pytest

import fiveaxis as fx

SEED = 14


def rotation(axis: np.ndarray, degrees: float) -> np.ndarray:
    """Rodrigues' rotation matrix, right-hand rule."""
    a = axis / np.linalg.norm(axis)
    t = math.radians(degrees)
    k = np.array([[0, -a[2], a[1]], [a[2], 0, -a[0]], [-a[1], a[0], 0]])
    return np.eye(3) + math.sin(t) * k + (1 - math.cos(t)) * (k @ k)


def affine(axis: np.ndarray, center: np.ndarray, degrees: float) -> np.ndarray:
    """p -> c + R (p - c) as a 4x4 matrix."""
    r = rotation(axis, degrees)
    m = np.eye(4)
    m[:3, :3] = r
    m[:3, 3] = center - r @ center
    return m


def reference_forward(machine: fx.Machine, joints: np.ndarray, length: float) -> Tuple[np.ndarray, np.ndarray]:
    """machine-model.md §3 for one machine position."""
    n_linear = len(machine.linear_axes)
    t0 = np.array(machine.tool_direction)
    head = np.eye(4)
    table = np.eye(4)
    for k, ax in enumerate(machine.rotary_axes):
        m = affine(np.array(ax["axis"]), np.array(ax["center"]), joints[n_linear + k])
        if ax["on"] == "head":
            head = head @ m
        else:
            table = table @ m
    tip_m = joints[:3] + (head @ np.append(-length * t0, 1.0))[:3]
    dir_m = head[:3, :3] @ t0
    inv = np.linalg.inv(table)
    return (inv @ np.append(tip_m, 1.0))[:3], table[:3, :3].T @ dir_m


def unit(rng: random.Random) -> List[float]:
    while True:
        v = [rng.gauss(0, 1) for _ in range(3)]
        n = math.sqrt(sum(x * x for x in v))
        if n > 1e-3:
            return [x / n for x in v]


def random_machine(rng: random.Random) -> fx.Machine:
    """A random two-rotary machine as a machine file: any arrangement,
    axis-aligned or arbitrary rotation lines, centres within ±300 mm, no
    rotary limits."""
    sides = rng.choice([("head", "head"), ("table", "table"), ("head", "table"), ("table", "head")])
    kind = "head" if sides == ("head", "head") else "table" if sides == ("table", "table") else "mixed"
    axes: List[List[float]] = []
    while len(axes) < 2:
        a = rng.choice([[1.0, 0, 0], [0, 1.0, 0], [0, 0, 1.0], [0, 0, -1.0]]) if rng.random() < 0.5 else unit(rng)
        if axes and abs(float(np.dot(axes[0], a))) > 0.9:
            continue
        axes.append(a)
    tool = [0.0, 0.0, 1.0] if rng.random() < 0.7 else unit(rng)
    text = [f'name = "random {SEED}"', f'type = "{kind}"', f"tool_direction = {tool}"]
    for name in "XYZ":
        text += ["[[linear]]", f'name = "{name}"', "min = -2000.0", "max = 2000.0"]
    for name, side, a in zip("AC", sides, axes):
        c = [round(rng.uniform(-300, 300), 3) for _ in range(3)]
        text += ["[[rotary]]", f'name = "{name}"', f'on = "{side}"', f"axis = {a}", f"center = {c}"]
    return fx.Machine.from_toml("\n".join(text) + "\n", "random.toml")


def random_cases(count: int) -> List[Tuple[fx.Machine, np.ndarray, np.ndarray]]:
    rng = random.Random(SEED)
    out = []
    for _ in range(count):
        m = random_machine(rng)
        n = 50
        joints = np.column_stack(
            [np.array([rng.uniform(-500, 500) for _ in range(n)]) for _ in range(3)]
            + [np.array([rng.uniform(-400, 400) for _ in range(n)]) for _ in range(2)]
        )
        lengths = np.array([rng.uniform(0, 300) for _ in range(n)])
        out.append((m, joints, lengths))
    return out


CASES = random_cases(24)


@pytest.mark.parametrize("case", range(len(CASES)))
def test_forward_is_the_machine_model(case: int) -> None:
    m, joints, lengths = CASES[case]
    tips, dirs = m.forward(joints, lengths)
    assert tips.shape == (len(joints), 3) and dirs.shape == (len(joints), 3)
    for i in range(len(joints)):
        tip, d = reference_forward(m, joints[i], lengths[i])
        assert np.allclose(tips[i], tip, rtol=0, atol=1e-9), (m.to_toml(), joints[i])
        assert np.allclose(dirs[i], d, rtol=0, atol=1e-12)


def assert_reaches(m: fx.Machine, joints: np.ndarray, lengths: np.ndarray, tips: np.ndarray, dirs: np.ndarray) -> None:
    for i in range(len(joints)):
        tip, d = reference_forward(m, joints[i], lengths[i])
        assert np.linalg.norm(tip - tips[i]) <= 1e-6, (i, tip, tips[i])
        angle = math.atan2(np.linalg.norm(np.cross(d, dirs[i])), float(np.dot(d, dirs[i])))
        assert angle <= 1e-9, (i, d, dirs[i])


@pytest.mark.parametrize("case", range(len(CASES)))
def test_every_inverse_solution_reaches_the_pose(case: int) -> None:
    m, joints, lengths = CASES[case]
    tips, dirs = m.forward(joints, lengths)
    inv = m.inverse(tips, dirs, lengths)
    assert inv.joints.shape == (len(joints), 2, 5)
    # Every direction forward kinematics reached is reachable.
    assert (inv.count >= 1).all()
    for s in range(2):
        has = inv.count > s
        assert_reaches(m, inv.joints[has, s], lengths[has], tips[has], dirs[has])
        assert np.isnan(inv.joints[~has, s]).all()
    # Away from the singular direction the angles that made the pose are
    # one of the solutions (modulo 360).
    for i in range(len(joints)):
        if inv.free_axis[i] >= 0:
            continue
        wanted = (joints[i, 3:] + 180.0) % 360.0 - 180.0
        found = [(inv.joints[i, s, 3:] + 180.0) % 360.0 - 180.0 for s in range(inv.count[i])]
        gaps = [np.abs((f - wanted + 180.0) % 360.0 - 180.0).max() for f in found]
        assert min(gaps) < 1e-6, (i, joints[i], found)


@pytest.mark.parametrize("case", range(len(CASES)))
def test_the_control_choice_reaches_the_pose(case: int) -> None:
    m, joints, lengths = CASES[case]
    tips, dirs = m.forward(joints, lengths)
    chosen, reached = m.choose(tips, dirs, lengths)
    assert reached.all()
    assert_reaches(m, chosen, lengths, tips, dirs)
    # Along the path each choice is one of the solutions' 360° repeats,
    # and no other repeat of any solution is closer in total rotary motion
    # (the FANUC rule "shortest").
    previous = np.zeros(2)
    inv = m.inverse(tips, dirs, lengths, held=(0.0, 0.0))
    for i in range(len(joints)):
        motion = np.abs(chosen[i, 3:] - previous).sum()
        for s in range(inv.count[i]):
            pair = inv.joints[i, s, 3:]
            nearest = previous + ((pair - previous + 180.0) % 360.0 - 180.0)
            if inv.free_axis[i] < 0:
                assert motion <= np.abs(nearest - previous).sum() + 1e-6
        previous = chosen[i, 3:]


def test_builtin_machines_round_trip() -> None:
    rng = np.random.default_rng(SEED)
    for name in fx.machines():
        m = fx.Machine(name)
        k = len(m.axes)
        joints = rng.uniform(-100, 100, (200, k))
        if k > 3:
            joints[:, 3:] = rng.uniform(-90, 90, (200, k - 3))
        tips, dirs = m.forward(joints, 80.0)
        inv = m.inverse(tips, dirs, 80.0)
        assert (inv.count >= 1).all(), name
        assert_reaches(m, inv.joints[:, 0], np.full(200, 80.0), tips, dirs)


def test_one_point_and_broadcast_lengths() -> None:
    m = fx.Machine("trunnion-ac")
    tips, dirs = m.forward([0, 0, 0, -30, 45], [100.0])
    assert tips.shape == (1, 3)
    t2, _ = m.forward(np.zeros((3, 5)), [0.0, 50.0, 100.0])
    assert np.allclose(t2[:, 2], [0.0, -50.0, -100.0])
