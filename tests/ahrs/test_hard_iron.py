"""The hard-iron offset from the gyro (:mod:`strapdown.ahrs.hard_iron`) and its use by
:func:`strapdown.ahrs.offline_ekf`."""

from __future__ import annotations

import numpy as np
import pytest

import strapdown.ahrs._kernel as K
from strapdown.ahrs import AhrsConfig, offline_ekf
from strapdown.ahrs.hard_iron import SPREAD_MAX, STEADIER_MAX, hard_iron
from strapdown.rotation.dcm import dcm_from_quat
from strapdown.rotation.error import attitude_error_angle
from strapdown.rotation.quaternion import quat_multiply

H = 0.01
M_N = np.array([0.0, 20.0, -40.0])  # µT, ENU


def _turning(n, axes=(1.0, 1.0, 1.0)):
    """Interval gyro samples of a body turning about three axes (or those of ``axes`` not
    zero), the attitude they give exactly (the gyro path itself) and the ideal field."""
    t = np.arange(n) * H
    w = np.column_stack([axes[0] * 1.2 * np.sin(1.3 * t), axes[1] * 0.9 * np.cos(0.7 * t),
                         axes[2] * 0.8 * np.sin(2.1 * t + 0.4)])
    q = np.empty((n, 4))
    K.gyro_path(w, np.zeros((n, 3)), H, True, q)
    m = np.einsum("nji,j->ni", dcm_from_quat(q), M_N)
    return t, w, q, m


def test_an_offset_is_recovered_whatever_the_unit():
    """Exact samples: the offset to 1e-9 of the field, all of the residual explained, the
    halves in agreement; the field's unit scales the offset and nothing else."""
    t, w, _, m = _turning(3000)
    b = np.array([9.0, -14.0, 6.0])
    est = hard_iron(t, w, m + b)
    assert est.observed == 3
    assert np.allclose(est.offset, b, rtol=0, atol=1e-9 * np.linalg.norm(M_N))
    assert est.explained == pytest.approx(1.0, abs=1e-12) and est.spread < 1e-9
    assert est.steadier < 1e-6  # |m − b| is the Earth field's norm, constant
    scaled = hard_iron(t, w, 1000.0 * (m + b))
    assert np.allclose(scaled.offset, 1000.0 * b, rtol=1e-9, atol=0)
    assert scaled.explained == pytest.approx(est.explained, abs=1e-12)


def test_a_single_axis_turn_leaves_its_axis_unobserved():
    """About one body axis only (a pendulum): ``I − R`` never sees the offset along it;
    that component is left at zero and the other two are recovered."""
    t, w, _, m = _turning(3000, axes=(1.0, 0.0, 0.0))
    b = np.array([9.0, -14.0, 6.0])
    est = hard_iron(t, w, m + b)
    assert est.observed == 2
    assert est.offset[0] == pytest.approx(0.0, abs=1e-9)
    assert np.allclose(est.offset[1:], b[1:], rtol=0, atol=1e-6)


def test_a_calibrated_field_explains_nothing():
    rng = np.random.default_rng(2)
    t, w, _, m = _turning(3000)
    est = hard_iron(t, w, m + rng.normal(0.0, 0.3, m.shape))
    assert est.explained < 0.01 and est.steadier > STEADIER_MAX


def test_offline_filter_subtracts_a_constant_offset_only():
    """A 30 µT offset (two thirds of the field): offline_ekf subtracts the estimate and its
    attitude error falls; an offset present in the first half only (a magnet taken off) is
    not a hard iron (the halves disagree) and is left; so is a calibrated field."""
    n = 4000
    t, w, q, m = _turning(n)
    rng = np.random.default_rng(7)
    acc = np.einsum("nji,j->ni", dcm_from_quat(q), [0.0, 0.0, 9.80665])
    acc += rng.normal(0.0, 0.02, acc.shape)
    m = m + rng.normal(0.0, 0.3, m.shape)
    b = np.array([18.0, -20.0, 12.0])
    r = offline_ekf(t, w, acc, m + b, q0=q[0])
    off = offline_ekf(t, w, acc, m + b, q0=q[0],
                      config=AhrsConfig(offline_hard_iron_min_explained=2.0))
    assert r.mag_offset is not None and off.mag_offset is None
    assert np.allclose(r.mag_offset, b, rtol=0, atol=0.5)
    e_r, e_off = (np.sqrt(np.mean(attitude_error_angle(x.q, q) ** 2)) for x in (r, off))
    assert e_r < 0.5 * e_off
    half = m + np.where(np.arange(n)[:, None] < n // 2, b, 0.0)
    est = hard_iron(t, w, half)
    assert est.spread > SPREAD_MAX
    assert offline_ekf(t, w, acc, half, q0=q[0]).mag_offset is None
    assert offline_ekf(t, w, acc, m, q0=q[0]).mag_offset is None


def test_bad_input_names_the_problem():
    t, w, _, m = _turning(50)
    with pytest.raises(ValueError, match=r"rates must have shape \(50, 3\)"):
        hard_iron(t, w[:, :2], m)
    with pytest.raises(ValueError, match=r"mag must have shape \(50, 3\)"):
        hard_iron(t, w, m[:, :2])
    with pytest.raises(ValueError, match="non-monotonic time stamp at row 1"):
        hard_iron(t[::-1], w, m)
    with pytest.raises(ValueError, match="mag contains NaN or infinity"):
        hard_iron(t, w, np.where(np.arange(50)[:, None] == 3, np.nan, m))
    with pytest.raises(ValueError, match="fewer than two spans"):
        hard_iron(t[:11], w[:11], m[:11], span_s=0.1)


def test_quat_multiply_is_the_convention_used():
    """The gyro path composes body-frame increments on the right (q ⊗ δq), as the
    spans' ``R = D_{k+d}ᵀ D_k`` assumes."""
    _, w, q, _ = _turning(3)
    step = np.empty((2, 4))
    K.gyro_path(w[1:], np.zeros((2, 3)), H, True, step)
    assert np.allclose(quat_multiply(q[1], step[1]), q[2], atol=1e-15)


def test_cli_offline_says_what_it_subtracted(tmp_path, capsys):
    """``strapdown ahrs`` on a field with a hard iron: a note on stderr and the offset in
    the metadata — offline the whole record's estimate, causal the online estimate's at the
    end (``AhrsConfig.hard_iron_s``; the offset applied follows the estimate when it moves
    by more than ``SPREAD_MAX`` of itself: 3.3 % off here)."""
    import json

    from strapdown.cli import main

    n = 3000
    t, w, q, m = _turning(n)
    acc = np.einsum("nji,j->ni", dcm_from_quat(q), [0.0, 0.0, 9.80665])
    b = np.array([18.0, -20.0, 12.0])
    np.savetxt(tmp_path / "imu.csv", np.column_stack([t, w, acc, m + b]), delimiter=",",
               header="t,gx,gy,gz,ax,ay,az,mx,my,mz", comments="")
    base = ["ahrs", "--imu", str(tmp_path / "imu.csv"), "--gyro-units", "rad/s",
            "--acc-units", "m/s2"]
    assert main([*base, "--offline", "--out", str(tmp_path / "off.csv")]) == 0
    assert "hard-iron offset" in capsys.readouterr().err
    meta = json.loads((tmp_path / "off.csv.meta.json").read_text())
    assert np.allclose(meta["mag_hard_iron_subtracted"], b, atol=1e-6)
    assert main([*base, "--out", str(tmp_path / "causal.csv")]) == 0
    assert "estimated it online" in capsys.readouterr().err
    online = json.loads((tmp_path / "causal.csv.meta.json").read_text())[
        "mag_hard_iron_subtracted"]
    assert np.linalg.norm(np.subtract(online, b)) < SPREAD_MAX * np.linalg.norm(b)


def test_the_compiled_sums_equal_a_plain_numpy_reference():
    """``_kernel.hard_iron_sums`` against the spans written with numpy (``R = D_{k+d}ᵀ D_k``,
    ``A = I − R``, ``r = m_{k+d} − R m_k``) and against its own plain Python."""
    rng = np.random.default_rng(4)
    _, _, q, m = _turning(600)
    m = m + rng.normal(0.0, 0.3, m.shape) + [5.0, -3.0, 2.0]
    d, lo, hi = 7, 11, 590
    i = np.arange(lo, hi)
    r_ = np.einsum("nji,njk->nik", dcm_from_quat(q[i + d]), dcm_from_quat(q[i]))
    a = np.eye(3) - r_
    r = m[i + d] - np.einsum("nij,nj->ni", r_, m[i])
    normal, rhs = np.zeros((3, 3)), np.zeros(3)
    rr = K.hard_iron_sums(q, m, d, lo, hi, normal, rhs)
    assert rr == pytest.approx(float(np.sum(r * r)), rel=1e-12)
    assert np.allclose(normal, np.einsum("nji,njk->ik", a, a), rtol=1e-12, atol=1e-12)
    assert np.allclose(rhs, np.einsum("nji,nj->i", a, r), rtol=1e-12, atol=1e-10)
    n2, r2 = np.zeros((3, 3)), np.zeros(3)
    assert K.hard_iron_sums.py_func(q, m, d, lo, hi, n2, r2) == pytest.approx(rr, rel=1e-14)
    assert np.allclose(n2, normal, rtol=1e-14, atol=0) and np.allclose(r2, rhs, rtol=1e-13)


def _online(n, b, axes=(1.0, 1.0, 1.0), seed=5, **cfg):
    """The causal filter on the turning body with the field ``m + b`` (noisy, µT) and on
    the calibrated field: (result with b, result without, true attitude)."""
    from strapdown.ahrs import ekf

    rng = np.random.default_rng(seed)
    t, w, q, m = _turning(n, axes)
    acc = np.einsum("nji,j->ni", dcm_from_quat(q), [0.0, 0.0, 9.80665])
    m = m + 0.2 * rng.standard_normal(m.shape)
    config = AhrsConfig(**cfg)
    return ekf(t, w, acc, m + b, config=config), ekf(t, w, acc, m, config=config), q


def _spread_deg(q_est, q_true):
    """RMS angle of the reference-frame error ``q_est ⊗ q_true*`` about its mean: the error
    left after a constant alignment (the start's heading, which a field with an offset at
    the start's TRIAD turned and the carried-over reference keeps, removed)."""
    from strapdown.rotation.quaternion import quat_conjugate

    e = quat_multiply(q_est, quat_conjugate(q_true))
    e *= np.where(e[:, :1] < 0, -1.0, 1.0)
    mean = e.mean(axis=0)
    mean /= np.linalg.norm(mean)
    ang = attitude_error_angle(e, np.broadcast_to(mean, e.shape))
    return float(np.degrees(np.sqrt(np.mean(ang ** 2))))


def test_online_estimate_finds_the_offset_and_carries_the_heading_over():
    """The causal filter's online hard-iron estimate (``AhrsConfig.hard_iron_s``): on a
    turning body with an offset of 40 % of the field it applies an offset within
    ``SPREAD_MAX`` of the truth, flags the change (``MAG_OFFSET``) within 30 s, the
    attitude does not jump there (the error changes by less than 0.2° from the sample
    before), and after it the error left by a constant alignment is within 0.1° of the
    calibrated field's run. Switched off (``hard_iron_s=0``), the offset's error stays
    (more than 1° above it)."""
    from strapdown.ahrs import MeasurementFlag

    b = np.array([9.0, -14.0, 6.0])
    res, clean, q = _online(6000, b)
    assert res.mag_offset is not None and clean.mag_offset is None
    assert np.linalg.norm(res.mag_offset - b) < SPREAD_MAX * np.linalg.norm(b)
    changed = np.flatnonzero(res.flags & MeasurementFlag.MAG_OFFSET)
    assert changed.size >= 1 and res.t[changed[0]] < 30.0
    k = changed[0]
    step = attitude_error_angle(res.q[k - 1:k + 1], q[k - 1:k + 1])  # error before, after
    assert abs(np.degrees(step[1] - step[0])) < 0.2
    after = slice(changed[-1] + 500, None)
    e_clean = _spread_deg(clean.q[after], q[after])
    assert _spread_deg(res.q[after], q[after]) < e_clean + 0.1
    off, _, _ = _online(6000, b, hard_iron_s=0.0)
    assert off.mag_offset is None
    assert _spread_deg(off.q[after], q[after]) > e_clean + 1.0


def test_online_estimate_leaves_a_calibrated_field_alone():
    """A calibrated field (noise only): the estimate explains nothing, no offset is ever
    applied, and the attitudes equal those of the filter without the estimate bit for bit."""
    from strapdown.ahrs import MeasurementFlag

    _, clean, _ = _online(4000, np.zeros(3))
    _, off, _ = _online(4000, np.zeros(3), hard_iron_s=0.0)
    assert clean.mag_offset is None
    assert not np.any(clean.flags & MeasurementFlag.MAG_OFFSET)
    assert np.array_equal(clean.q, off.q)
