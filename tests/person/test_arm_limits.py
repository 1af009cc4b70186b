"""Pose-dependent arm limits (assistive_compiler.person.arm_limits): the analytic model's
properties, the user-MLP loader against a hand-written forward pass in the reference's input
convention (paper §III-C), the loader's error messages, the revert guard, and the per-call cost."""

from __future__ import annotations

import math
import time

import numpy as np
import pytest

from assistive_compiler.person.arm_limits import (
    AnalyticArmLimits,
    ArmLimitGuard,
    ArmLimitModel,
    MLPArmLimits,
    arm_box,
    mirror_pose,
    reference_input,
)
from assistive_compiler.person.skeleton import JOINT_LIMITS_DEG

D = np.radians
SIDES = ("right", "left")


@pytest.fixture(scope="module")
def model() -> AnalyticArmLimits:
    return AnalyticArmLimits()


def pose(qx: float, qy: float, qz: float, qe: float, side: str = "right") -> np.ndarray:
    """Degrees -> radians; right-arm numbers, mirrored for the left arm."""
    q = D([qx, qy, qz, qe])
    return q if side == "right" else mirror_pose(q)


# ----------------------------------------------------------------------------------------------
# Analytic model
# ----------------------------------------------------------------------------------------------


def test_protocol_and_shapes(model):
    assert isinstance(model, ArmLimitModel)
    one = model.valid(np.zeros(4), "right")
    assert one.shape == () and one.dtype == bool
    many = model.valid(np.zeros((7, 4)), "left")
    assert many.shape == (7,) and many.dtype == bool and many.all()
    with pytest.raises(ValueError, match="shape"):
        model.valid(np.zeros(3), "right")
    with pytest.raises(ValueError, match="side"):
        model.valid(np.zeros(4), "both")
    assert not model.valid(np.array([math.nan, 0, 0, 0]), "right")


@pytest.mark.parametrize("side", SIDES)
def test_zero_pose_valid(model, side):
    assert model.valid(np.zeros(4), side)
    assert model.valid(np.zeros((1, 4)), side).all()
    # The reference's box starts at 5 degrees of shoulder_x (paper §III-A); strict_box keeps it.
    assert not AnalyticArmLimits(strict_box=True).valid(np.zeros(4), side)


def test_box_is_the_reference_box(model):
    for side in SIDES:
        lo, hi = model.box(side)
        names = [f"{side}_shoulder_x", f"{side}_shoulder_y", f"{side}_shoulder_z", f"{side}_elbow"]
        ref = np.array([JOINT_LIMITS_DEG[n] for n in names], dtype=float)
        # Only the shoulder_x bound next to 0 is relaxed to 0 (the hanging neutral).
        exp_lo, exp_hi = D(ref[:, 0]), D(ref[:, 1])
        if side == "right":
            exp_lo[0] = 0.0
        else:
            exp_hi[0] = 0.0
        np.testing.assert_allclose(lo, exp_lo, atol=1e-12)
        np.testing.assert_allclose(hi, exp_hi, atol=1e-12)
        strict_lo, strict_hi = AnalyticArmLimits(strict_box=True).box(side)
        np.testing.assert_allclose(strict_lo, D(ref[:, 0]))
        np.testing.assert_allclose(strict_hi, D(ref[:, 1]))
        np.testing.assert_allclose(arm_box(side)[0], D(ref[:, 0]))


@pytest.mark.parametrize("side", SIDES)
def test_out_of_box_rejected(model, side):
    lo, hi = model.box(side)
    base = pose(30, 0, 0, -90, side)
    assert model.valid(base, side)
    eps = D(0.5)
    for j in range(4):
        for value in (lo[j] - eps, hi[j] + eps, lo[j] - 1.0, hi[j] + 2.0):
            q = base.copy()
            q[j] = value
            assert not model.valid(q, side), (side, j, np.degrees(value))
    # Random poses in a box widened by 40 degrees: every one outside the box is invalid.
    rng = np.random.default_rng(7)
    q = rng.uniform(lo - D(40), hi + D(40), size=(5000, 4))
    outside = np.any((q < lo) | (q > hi), axis=1)
    assert outside.sum() > 1000
    assert not model.valid(q[outside], side).any()


def test_mirror_symmetry(model):
    rng = np.random.default_rng(1234)
    lo, hi = model.box("right")
    q = rng.uniform(lo - D(20), hi + D(20), size=(1000, 4))
    right = model.valid(q, "right")
    left = model.valid(mirror_pose(q), "left")
    np.testing.assert_array_equal(right, left)
    assert 0.1 < right.mean() < 0.9  # a meaningful mix of both answers
    # and pose by pose through the scalar path
    for row in q[:200]:
        assert model.valid(row, "right") == model.valid(mirror_pose(row), "left")


def test_valid_fraction(model):
    rng = np.random.default_rng(2024)
    lo, hi = arm_box("right")  # the reference's pose-independent box (5...198 for shoulder_x)
    q = rng.uniform(lo, hi, size=(20000, 4))
    frac = float(model.valid(q, "right").mean())
    print(
        f"\nanalytic model: valid fraction of 20,000 uniform samples in the right-arm box = {frac:.3f} "
        f"(reference MLP: ~0.41)"
    )
    assert 0.25 <= frac <= 0.60


def test_scalar_and_vector_paths_agree(model):
    rng = np.random.default_rng(99)
    lo, hi = model.box("right")
    q = rng.uniform(lo - D(10), hi + D(10), size=(3000, 4))
    for side in SIDES:
        qs = q if side == "right" else mirror_pose(q)
        vec = model.valid(qs, side)
        one = np.array([bool(model.valid(row, side)) for row in qs])
        np.testing.assert_array_equal(vec, one)


@pytest.mark.parametrize("side", SIDES)
def test_reference_task_poses_valid(model, side):
    # Initial arm postures of the reference tasks (paper §III-B-2.6), right-arm numbers.
    for qx, qy, qz, qe in [
        (30, 0, 0, -90),
        (0, 0, 0, -90),
        (45, 0, 0, -90),
        (60, -60, 0, 0),
        (5, 0, 0, 0),
        (0, -90, 0, 0),
        (10, -40, 20, -125),
    ]:
        assert model.valid(pose(qx, qy, qz, qe, side), side), (qx, qy, qz, qe)


@pytest.mark.parametrize("side", SIDES)
def test_coupling_axial_rotation_vs_elevation(model, side):
    v = lambda *a: bool(model.valid(pose(*a, side=side), side))  # noqa: E731
    # 80 deg of external rotation: beyond the range with the arm at the side, fine at 90 abduction.
    assert not v(0, 0, -80, 0)
    assert v(90, 0, -80, 0)
    # 60 deg of internal rotation: fine at the side and at 90 abduction, not at 160 abduction.
    assert v(0, 0, 60, 0)
    assert v(90, 0, 60, 0)
    assert not v(160, 0, 60, 0)
    # Overhead the arm must be externally rotated: 170 abduction without rotation is invalid,
    # with 90 deg of external rotation valid; raised by flexion (hand behind the head) valid.
    assert not v(170, 0, 0, 0)
    assert v(170, 0, -90, 0)
    assert v(0, -170, 0, -90)
    # The width of the valid shoulder_z range (elbow straight, abduction plane) narrows with
    # elevation: about 160 deg at 90 abduction, about 115 at 160 (box: 180).
    qz = np.linspace(-90, 90, 721)
    widths = {}
    for abd in (90, 160):
        qs = np.array([pose(abd, 0, z, 0, side) for z in qz])
        widths[abd] = model.valid(qs, side).sum() * 0.25
    assert widths[90] == pytest.approx(160, abs=1)
    assert widths[160] < widths[90] - 30


@pytest.mark.parametrize("side", SIDES)
def test_coupling_joint_sinus(model, side):
    v = lambda *a: bool(model.valid(pose(*a, side=side), side))  # noqa: E731
    # Arm horizontal (90 abduction) swung behind the frontal plane by shoulder_y: 30 deg is
    # fine, 60 deg is not, although both are inside the pose-independent box.
    assert v(90, 30, 0, 0)
    assert not v(90, 60, 0, 0)
    # Swung across the front of the chest: 120 deg from the side is fine, 150 is not.
    assert v(90, -120, -60, 0)
    assert not v(90, -150, -60, 0)
    # Straight extension: 55 deg valid, 61 (inside the box's 61) not.
    assert v(0, 55, 0, 0)
    assert not v(0, 61, 0, 0)
    angles = np.degrees(model.humeral_angles(pose(90, 60, 0, 0, side), side)[0])
    np.testing.assert_allclose(angles[:2], [90, -60], atol=1e-9)  # elevation, plane of elevation


@pytest.mark.parametrize("side", SIDES)
def test_coupling_elbow_flexion_and_trunk(model, side):
    v = lambda *a: bool(model.valid(pose(*a, side=side), side))  # noqa: E731
    # Arm hanging, 70 deg of internal rotation: free with the elbow straight, but with the elbow
    # flexed 90 the forearm would pass through the abdomen. 50 deg with the elbow flexed is fine.
    assert v(0, 0, 70, 0)
    assert not v(0, 0, 70, -90)
    assert not v(0, 0, 70, -45)
    assert v(0, 0, 50, -90)
    # The same internal rotation with the upper arm abducted 60: the forearm clears the trunk.
    assert v(60, 0, 70, -90)


def test_humeral_angles_conventions(model):
    # At the side psi == shoulder_z; at 90 abduction psi == shoulder_z (forearm forward at 0);
    # at 90 flexion the ISB neutral has the forearm across the body (shoulder_z = +90 here).
    cases = [((0, 0, 35, 0), (0, 35)), ((90, 0, -40, 0), (90, -40)), ((0, -90, 90, 0), (90, 0))]
    for q, (theta, psi) in cases:
        t, _, p = np.degrees(model.humeral_angles(pose(*q), "right")[0])
        assert t == pytest.approx(theta, abs=1e-9)
        assert p == pytest.approx(psi, abs=1e-9)


# ----------------------------------------------------------------------------------------------
# User MLP (.npz)
# ----------------------------------------------------------------------------------------------


def _forward(weights, biases, activations, q, side):
    """Direct forward pass in the reference's convention (paper §III-C), one pose."""
    tz, tx, ty, qe = (float(a) for a in q)
    s = -1.0 if side == "right" else 1.0
    x = np.array(
        [(s * tz + 2 * np.pi) % (2 * np.pi), (tx + 2 * np.pi) % (2 * np.pi), s * ty, (-qe + 2 * np.pi) % (2 * np.pi)]
    )
    fns = {
        "tanh": np.tanh,
        "sigmoid": lambda z: 1 / (1 + np.exp(-z)),
        "relu": lambda z: np.maximum(z, 0),
        "linear": lambda z: z,
    }
    for w, b, a in zip(weights, biases, activations):
        x = fns[a](x @ w + b)
    return float(x[0])


HAND_PICKED = [
    (0, 0, 0, 0),
    (30, 0, 0, -90),
    (190, -170, 80, -120),
    (-45, 20, -30, -10),
    (120, -60, 45, -128),
    (5, 61, -90, 0),
    (198, -188, 90, -64),
    (-198, 10, 0, -30),
    (90, -90, 0, -45),
    (60, -120, -75, -100),
]


def _random_mlp(rng, sizes, picks, activations):
    ws = [rng.normal(scale=0.8, size=(a, b)) for a, b in zip(sizes[:-1], sizes[1:])]
    bs = [rng.normal(scale=0.3, size=b) for b in sizes[1:]]
    # Centre the output on the hand-picked poses so that both classes occur.
    linear_out = tuple(activations[:-1]) + ("linear",)
    logits = [_forward(ws, bs, linear_out, q, "right") for q in picks]
    bs[-1] = bs[-1] - np.median(logits) + 1e-3
    return ws, bs


def _save(path, ws, bs, **extra):
    arrays = {f"W{i}": w for i, w in enumerate(ws)} | {f"b{i}": b for i, b in enumerate(bs)}
    np.savez(path, **arrays, **extra)
    return path


@pytest.mark.parametrize("activations", [None, ("relu", "tanh", "sigmoid")])
def test_npz_matches_direct_forward_pass(tmp_path, activations):
    rng = np.random.default_rng(5)
    picks = D(np.array(HAND_PICKED, dtype=float))
    acts = activations or ("tanh", "tanh", "sigmoid")
    ws, bs = _random_mlp(rng, (4, 6, 5, 1), picks, acts)
    extra = {} if activations is None else {"activations": np.array(activations)}
    path = _save(tmp_path / "mlp.npz", ws, bs, **extra)
    mlp = MLPArmLimits.from_npz(path)
    assert mlp.activations == tuple(acts)
    assert isinstance(mlp, ArmLimitModel)
    seen = set()
    for side in SIDES:
        expected = np.array([_forward(ws, bs, acts, q, side) for q in picks])
        np.testing.assert_allclose(mlp.predict(picks, side), expected, rtol=1e-12, atol=1e-12)
        np.testing.assert_array_equal(mlp.valid(picks, side), expected >= 0.5)
        for q, e in zip(picks, expected):
            assert bool(mlp.valid(q, side)) == (e >= 0.5)
            seen.add(bool(e >= 0.5))
        # the conversion makes the network mirror-symmetric too
        np.testing.assert_allclose(mlp.predict(mirror_pose(picks), "left"), mlp.predict(picks, "right"))
    assert seen == {True, False}


def test_reference_input_conversion():
    q = D([190.0, -170.0, 80.0, -120.0])
    r = reference_input(q, "right")[0]
    l_ = reference_input(q, "left")[0]
    np.testing.assert_allclose(np.degrees(r), [170, 190, -80, 120], atol=1e-9)
    np.testing.assert_allclose(np.degrees(l_), [190, 190, 80, 120], atol=1e-9)


def _good_arrays(rng):
    ws = [rng.normal(size=(4, 3)), rng.normal(size=(3, 2)), rng.normal(size=(2, 1))]
    bs = [rng.normal(size=3), rng.normal(size=2), rng.normal(size=1)]
    return ws, bs


@pytest.mark.parametrize(
    "mutate, pattern",
    [
        (lambda a: a.pop("W1"), r"missing arrays: W1"),
        (lambda a: a.pop("b0"), r"missing arrays: b0"),
        (lambda a: [a.pop(k) for k in list(a) if k.startswith("W")], r"missing arrays: no W0"),
        (lambda a: a.update(W1=np.ones((4, 2))), r"shape mismatch between layers: W0 outputs 3 but W1 takes 4"),
        (lambda a: a.update(b1=np.ones(5)), r"shape mismatch: b1 has shape \(5,\)"),
        (lambda a: a.update(W0=np.ones((5, 3))), r"input size must be 4.*W0 takes 5"),
        (lambda a: a.update(W2=np.ones((2, 3)), b2=np.ones(3)), r"output size must be 1, W2 gives 3"),
        (lambda a: a.update(W0=np.ones(12)), r"W0 must be 2-D"),
        (lambda a: a.update(activations=np.array(["tanh", "sigmoid"])), r"'activations' has 2 entries for 3 layers"),
        (lambda a: a.update(activations=np.array(["tanh", "swish", "sigmoid"])), r"unknown activation"),
        (lambda a: a.update(activations=np.array([1.0, 2.0, 3.0])), r"'activations' must be an array of strings"),
        (lambda a: a.update(b2=np.array([np.nan])), r"non-finite"),
    ],
)
def test_npz_errors(tmp_path, mutate, pattern):
    rng = np.random.default_rng(0)
    ws, bs = _good_arrays(rng)
    arrays = {f"W{i}": w for i, w in enumerate(ws)} | {f"b{i}": b for i, b in enumerate(bs)}
    MLPArmLimits.from_npz(_save(tmp_path / "ok.npz", ws, bs))  # the unmutated file loads
    mutate(arrays)
    path = tmp_path / "bad_model.npz"
    np.savez(path, **arrays)
    with pytest.raises(ValueError, match=pattern) as err:
        MLPArmLimits.from_npz(path)
    assert str(path) in str(err.value)


def test_npz_unreadable_files(tmp_path):
    missing = tmp_path / "nope.npz"
    with pytest.raises(ValueError, match="no such file") as err:
        MLPArmLimits.from_npz(missing)
    assert str(missing) in str(err.value)
    junk = tmp_path / "junk.npz"
    junk.write_text("not a zip")
    with pytest.raises(ValueError, match="not a readable .npz") as err:
        MLPArmLimits.from_npz(junk)
    assert str(junk) in str(err.value)


# ----------------------------------------------------------------------------------------------
# Guard
# ----------------------------------------------------------------------------------------------


@pytest.mark.parametrize("side", SIDES)
def test_guard_reverts_to_last_valid(model, side):
    guard = ArmLimitGuard(model, side)
    q0 = pose(30, 0, 0, -90, side)
    q1 = pose(40, -20, 10, -80, side)
    bad1 = pose(0, 0, 80, -90, side)  # forearm through the abdomen
    bad2 = pose(170, 0, 0, 0, side)  # overhead without external rotation
    q2 = pose(0, -90, 0, 0, side)
    assert model.valid(q1, side) and model.valid(q2, side)
    assert not model.valid(bad1, side) and not model.valid(bad2, side)

    assert guard.reset(q0) is True
    np.testing.assert_array_equal(guard.last_valid, q0)
    out, rev = guard.check(q1)
    assert not rev and np.array_equal(out, q1)
    out, rev = guard.check(bad1)
    assert rev and np.array_equal(out, q1)
    out, rev = guard.check(bad2)
    assert rev and np.array_equal(out, q1)
    out[:] = 0.0  # the returned pose is a copy
    np.testing.assert_array_equal(guard.last_valid, q1)
    out, rev = guard.check(q2)
    assert not rev and np.array_equal(out, q2)
    out, rev = guard.check(bad1)
    assert rev and np.array_equal(out, q2)

    # Nothing valid seen yet: the reference leaves the pose alone.
    assert guard.reset() is False
    out, rev = guard.check(bad1)
    assert not rev and np.array_equal(out, bad1)
    assert guard.reset(bad2) is False and guard.last_valid is None
    out, rev = guard.check(q0)
    assert not rev and np.array_equal(out, q0)
    out, rev = guard.check(bad2)
    assert rev and np.array_equal(out, q0)


def test_guard_with_any_model_and_bad_input():
    class ElbowOnly:
        def valid(self, q, side):
            q = np.asarray(q, dtype=float)
            return q[..., 3] > -1.0

    guard = ArmLimitGuard(ElbowOnly(), "left")
    guard.reset(np.zeros(4))
    out, rev = guard.check([0.1, 0.2, 0.3, -1.5])
    assert rev and np.array_equal(out, np.zeros(4))
    with pytest.raises(ValueError, match="shape"):
        guard.check(np.zeros((2, 4)))
    with pytest.raises(ValueError, match="side"):
        ArmLimitGuard(ElbowOnly(), "middle")
    with pytest.raises(TypeError):
        ArmLimitGuard(object(), "right")  # type: ignore[arg-type]


# ----------------------------------------------------------------------------------------------
# Cost
# ----------------------------------------------------------------------------------------------


def _median_call_us(model, q, side, n=2000):
    for _ in range(50):
        model.valid(q, side)
    times = np.empty(n)
    for i in range(n):
        t = time.perf_counter()
        model.valid(q, side)
        times[i] = time.perf_counter() - t
    return float(np.median(times) * 1e6)


def test_cost_per_call(model, tmp_path):
    rng = np.random.default_rng(3)
    sizes = (4, 64, 64, 64, 1)  # the reference network's shape
    ws = [rng.normal(scale=0.3, size=(a, b)) for a, b in zip(sizes[:-1], sizes[1:])]
    bs = [rng.normal(scale=0.1, size=b) for b in sizes[1:]]
    mlp = MLPArmLimits.from_npz(_save(tmp_path / "ref_shape.npz", ws, bs))
    q = pose(30, -20, 10, -90)
    analytic_us = _median_call_us(model, q, "right")
    mlp_us = _median_call_us(mlp, q, "right")
    print(f"\nvalid() median per call on one pose: analytic {analytic_us:.1f} us, MLP 4-64-64-64-1 {mlp_us:.1f} us")
    assert analytic_us < 1000.0
    assert mlp_us < 1000.0


# ----------------------------------------------------------------------------------------------
# Geometry cross-check against the real person model
# ----------------------------------------------------------------------------------------------


def test_geometry_matches_person_forward_kinematics(model, tmp_path):
    """The analytic model's upper-arm and forearm directions equal pybullet's forward kinematics
    of the rendered person template, for both arms (so its joint convention and mirroring are
    the body's)."""
    p = pytest.importorskip("pybullet")
    xacro = pytest.importorskip("xacro")
    from assistive_compiler.person import body

    doc = xacro.process_file(str(body.PERSON_TEMPLATE), mappings=dict(body.body_measurements("male").xacro_args()))
    urdf = tmp_path / "person.urdf"
    urdf.write_text(doc.toprettyxml(indent="  "))
    cid = p.connect(p.DIRECT)
    try:
        bid = p.loadURDF(str(urdf), useFixedBase=True, physicsClientId=cid)
        joint = {}
        link = {}
        for i in range(p.getNumJoints(bid, physicsClientId=cid)):
            info = p.getJointInfo(bid, i, physicsClientId=cid)
            joint[info[1].decode()] = i
            link[info[12].decode()] = i

        def pos(name):
            return np.array(p.getLinkState(bid, link[name], computeForwardKinematics=True, physicsClientId=cid)[4])

        rng = np.random.default_rng(11)
        for side in SIDES:
            lo, hi = arm_box(side)
            for q in rng.uniform(lo, hi, size=(40, 4)):
                for j, name in zip(q, ("shoulder_x", "shoulder_y", "shoulder_z", "elbow")):
                    p.resetJointState(bid, joint[f"{side}_{name}"], j, physicsClientId=cid)
                sh, el, wr = pos(f"{side}_shoulder"), pos(f"{side}_elbow"), pos(f"{side}_wrist")
                frames = model._frames((q if side == "right" else mirror_pose(q))[None])
                d = np.array(frames[0:3]).ravel()
                v = np.array(frames[6:9]).ravel()
                if side == "left":  # the model works in the mirrored (right-arm) frame
                    d[0], v[0] = -d[0], -v[0]
                np.testing.assert_allclose((el - sh) / np.linalg.norm(el - sh), d, atol=1e-5)
                np.testing.assert_allclose((wr - el) / np.linalg.norm(wr - el), v, atol=1e-5)
    finally:
        p.disconnect(cid)
