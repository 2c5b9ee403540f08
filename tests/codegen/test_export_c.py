"""Generated C: compiles strictly, and matches the Python library over 1e5 steps."""

from __future__ import annotations

import math

import numpy as np
import pytest

from c_harness import build, drive
from strapdown.algorithms import rate
from strapdown.algorithms.coning import coefficient_set
from strapdown.algorithms.structures import conventional, realtime, single_chain
from strapdown.codegen.export_c import export_c
from strapdown.truth.motions import SpinConing

STEPS = 100_000
H = 1e-4
MOTION = SpinConing(math.radians(2.0), 2 * math.pi * 5, math.radians(3600.0))
def _increments():
    return MOTION.increments(np.arange(STEPS + 1) * H)


def _rates():
    t = np.arange(STEPS + 1) * H
    return t, MOTION.rate(t)


CASES = [("rotvec", "conventional", n) for n in (1, 2, 3, 5)] + \
        [("rotvec", "realtime", n) for n in (2, 3, 5)] + \
        [("rotvec", "single-chain", n) for n in (2, 3, 5)] + \
        [("rate-single", "conventional", 0), ("rate-three", "conventional", 0),
         ("rate-three", "sliding", 0), ("rk4", "conventional", 0)]


def _python(alg, structure, n, q0):
    if alg == "rotvec":
        th = _increments()
        if structure == "single-chain":
            return single_chain(th, n, h=H, q0=q0).q
        cs = coefficient_set("table3", n)
        if structure == "realtime":
            return realtime(th, cs, h=H, q0=q0).q
        m = th.shape[0] - th.shape[0] % n
        return conventional(th[:m], cs, h=H, q0=q0).q
    t, w = _rates()
    return rate.rate_attitude(t, w, algorithm=alg, structure=structure, q0=q0).q


@pytest.mark.parametrize(("alg", "structure", "n"), CASES)
def test_double_matches_python(tmp_path, alg, structure, n):
    q0 = MOTION.attitude(0.0)
    e, lib = build(tmp_path, algorithm=alg, structure=structure, subsamples=max(n, 1), h=H)
    x = _increments() if alg == "rotvec" else _rates()[1]
    c = drive(e, lib, x, q0)
    py = _python(alg, structure, n, q0)
    assert c.shape == py.shape
    assert np.max(np.abs(c - py)) <= 1e-13


@pytest.mark.parametrize(("alg", "structure", "n"), [("rotvec", "conventional", 3),
                                                      ("rotvec", "realtime", 3),
                                                      ("rate-three", "sliding", 0)])
def test_float_error_against_double(tmp_path, alg, structure, n, capsys):
    q0 = MOTION.attitude(0.0)
    x = _increments() if alg == "rotvec" else _rates()[1]
    e64, lib64 = build(tmp_path / "d", algorithm=alg, structure=structure, subsamples=max(n, 1),
                        h=H)
    e32, lib32 = build(tmp_path / "f", algorithm=alg, structure=structure, subsamples=max(n, 1),
                        h=H, real="float")
    d = drive(e64, lib64, x, q0)
    f = drive(e32, lib32, x, q0)
    err = np.max(np.minimum(np.abs(f - d).max(axis=1), np.abs(f + d).max(axis=1)))
    with capsys.disabled():
        print(f"\n  float vs double, {alg} {structure}: max quaternion difference {err:.2e}")
    assert err < 1e-2  # float32 round-off over 1e5 steps, reported above


def test_generated_code_properties(tmp_path):
    e = export_c(tmp_path, algorithm="rotvec", structure="conventional", subsamples=3)
    src = e.source + e.header
    assert "malloc" not in src and "free(" not in src
    assert "27/20" in src and "9/20" in src  # rational forms in comments
    assert "Li & Zhang 2017" in e.header
    import re

    calls = set(re.findall(r"\b(sqrt|sin|cos|tan|exp|log|pow|atan2|fabs)\(", e.source))
    assert calls <= {"sqrt", "sin", "cos"}
    assert e.ops["sin"] == 1 and e.ops["mul"] > 0


@pytest.mark.parametrize(("kw", "msg"), [
    ({"algorithm": "euler"}, "unknown algorithm"),
    ({"algorithm": "rotvec", "structure": "sliding"}, "rotvec supports the structures"),
    ({"algorithm": "rk4", "coefficients": "paper"}, "no coefficients"),
    ({"algorithm": "rotvec", "real": "half"}, "double or float"),
    ({"algorithm": "rotvec", "name": "9bad"}, "C identifier"),
])
def test_bad_export(tmp_path, kw, msg):
    with pytest.raises(ValueError, match=msg):
        export_c(tmp_path, **kw)


@pytest.mark.parametrize(("structure", "name", "n"), [("conventional", "miller", 3),
                                                      ("realtime", "lag", 4),
                                                      ("conventional", "eq6-printed", 3)])
def test_other_coefficient_sets_match(tmp_path, structure, name, n):
    q0 = MOTION.attitude(0.0)
    e, lib = build(tmp_path, algorithm="rotvec", structure=structure, subsamples=n,
                    coefficients=name, h=H)
    th = _increments()
    cs = coefficient_set(name, n)
    m = th.shape[0] - th.shape[0] % n
    py = (conventional(th[:m], cs, h=H, q0=q0) if structure == "conventional"
          else realtime(th, cs, h=H, q0=q0)).q
    c = drive(e, lib, th, q0)
    assert np.max(np.abs(c - py)) <= 1e-13


def test_rate_paper_coefficients_match(tmp_path):
    q0 = MOTION.attitude(0.0)
    e, lib = build(tmp_path, algorithm="rate-three", structure="conventional",
                    coefficients="paper", h=H)
    t, w = _rates()
    py = rate.rate_attitude(t, w, algorithm="rate-three", coefficients="paper", q0=q0).q
    assert np.max(np.abs(drive(e, lib, w, q0) - py)) <= 1e-13


@pytest.mark.parametrize(("structure", "n"), [("conventional", 2), ("conventional", 4),
                                              ("conventional", 6), ("single-chain", 2),
                                              ("single-chain", 3), ("single-chain", 6)])
def test_finite_amplitude_sets_match(tmp_path, structure, n):
    # triple cross products θ_m × (θ_i × θ_j) in C, the kernels' operations in their order
    from strapdown.algorithms.finite_amplitude import triple_terms
    from strapdown.codegen.export_c import generate

    q0 = MOTION.attitude(0.0)
    th = _increments()
    e, lib = build(tmp_path, algorithm="rotvec", structure=structure, subsamples=n, h=H,
                   coefficients="finite-amplitude")
    c = drive(e, lib, th, q0)
    if structure == "single-chain":
        py = single_chain(th, n, h=H, q0=q0, triple=True).q
        plain = single_chain(th, n, h=H, q0=q0).q
    else:
        m = th.shape[0] - th.shape[0] % n
        py = conventional(th[:m], coefficient_set("finite-amplitude", n), h=H, q0=q0).q
        plain = conventional(th[:m], coefficient_set("table3", n), h=H, q0=q0).q
    assert c.shape == py.shape
    assert np.max(np.abs(c - py)) <= 1e-13
    assert np.max(np.abs(py - plain)) > 1e-12  # the triple terms are there
    assert "malloc" not in e.source and "sd_triple_add" in e.source
    base = generate("rotvec", structure=structure, subsamples=n, h=H).ops
    terms = len(triple_terms(structure, n))  # N − 1, conventional N = 4, 5, 6: 5, 8, 9
    assert e.ops["mul"] - base["mul"] == 15 * terms
    assert e.ops["add"] - base["add"] == 9 * terms


def test_finite_amplitude_refused_in_realtime():
    from strapdown.codegen.export_c import generate

    with pytest.raises(ValueError, match="not realtime"):
        generate("rotvec", structure="realtime", subsamples=3, coefficients="finite-amplitude")


def test_designed_a6_set_exports_and_matches(tmp_path):
    # any CoefficientSet (here the a⁶ finite-amplitude design, 9 triple terms at N = 6)
    import ctypes
    import subprocess

    from c_harness import FLAGS, compiler
    from strapdown.codegen.export_c import generate_coefficient_set
    from strapdown.design import designer as D
    from strapdown.design import finite_amplitude as FA

    cs = FA.derive_triple_a6(FA.with_a6_triples(D.interval_structure(6))).coefficient_set(
        "finite-amplitude-a6")
    e = generate_coefficient_set(cs)
    (tmp_path / f"{e.name}.h").write_text(e.header)
    (tmp_path / f"{e.name}.c").write_text(e.source)
    lib = tmp_path / f"lib{e.name}.so"
    res = subprocess.run([compiler(), *FLAGS, "-o", str(lib), str(tmp_path / f"{e.name}.c"),
                          "-lm"], capture_output=True, text=True)
    assert res.returncode == 0, res.stderr
    q0 = MOTION.attitude(0.0)
    th = _increments()
    m = th.shape[0] - th.shape[0] % 6
    c = drive(e, ctypes.CDLL(str(lib)), th[:m], q0)
    py = conventional(th[:m], cs, h=H, q0=q0).q
    assert np.max(np.abs(c - py)) <= 1e-13
    assert e.ops["mul"] == 76 + 15 * 9 and e.ops["add"] == 65 + 9 * 9
    with pytest.raises(ValueError, match="CoefficientSet"):
        generate_coefficient_set("finite-amplitude")
