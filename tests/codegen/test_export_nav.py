"""Generated navigation C (coning + sculling, WGS-84 NED): compiles strictly, equals the
library to 1e-13 over a flight with turns and a climb, allocation-free, counted."""

from __future__ import annotations

import ctypes
import re

import numpy as np
import pytest

from c_harness import build
from strapdown.codegen.export_c import ALGORITHMS, export_c, generate
from strapdown.codegen.nav_c import nav_ops
from strapdown.navigation import navigate
from strapdown.truth.trajectory import EarthFlight, EarthSegment

H = 0.01
FLIGHT = EarthFlight([EarthSegment(20.0), EarthSegment(40.0, 3.0, 5.0), EarthSegment(20.0)],
                     lat_deg=48.0, lon_deg=11.0, height=600.0, speed=120.0, heading_deg=70.0,
                     ramp=4.0)


@pytest.fixture(scope="module")
def log():
    g, a = FLIGHT.increments(np.arange(round(FLIGHT.duration / H) + 1) * H)
    s0 = FLIGHT.state(np.array([0.0]))
    q0 = s0.q[0] / np.linalg.norm(s0.q[0])
    return g, a, np.array([FLIGHT.lat0, FLIGHT.lon0, FLIGHT.h0]), s0.velocity[0], q0


def _drive(e, lib, g, a, pos0, v0, q0):
    dbl = ctypes.POINTER(ctypes.c_double)

    def ptr(x):
        return x.ctypes.data_as(dbl)

    size = getattr(lib, f"{e.name}_state_size")
    size.restype = ctypes.c_ulong
    state = ctypes.create_string_buffer(int(size()))
    init = getattr(lib, f"{e.name}_init")
    init.argtypes = [ctypes.c_void_p, ctypes.c_double, dbl, dbl, dbl]
    pos0, v0, q0 = (np.ascontiguousarray(x, float) for x in (pos0, v0, q0))
    init(state, H, ptr(pos0), ptr(v0), ptr(q0))
    update = getattr(lib, f"{e.name}_update")
    update.restype = ctypes.c_int
    p, v, q = np.zeros(3), np.zeros(3), np.zeros(4)
    rows = []
    gs, as_ = np.ascontiguousarray(g), np.ascontiguousarray(a)
    for k in range(gs.shape[0]):
        if update(state, ptr(gs[k]), ptr(as_[k]), ptr(p), ptr(v), ptr(q)):
            rows.append(np.concatenate([p, v, q]))
    return np.array(rows), state, lib


@pytest.mark.parametrize(("structure", "n", "vset"), [
    ("conventional", 1, None), ("conventional", 2, None), ("conventional", 3, None),
    ("conventional", 4, None), ("conventional", 6, None), ("conventional", 3, "classical"),
    ("conventional", 4, "classical"), ("single-chain", 3, None), ("single-chain", 6, None)])
def test_nav_c_equals_the_library(tmp_path, log, structure, n, vset):
    """The C runs the library's default velocity set (what ``strapdown nav`` runs) unless told
    another with ``velocity_set``, as ``navigate`` does."""
    g, a, pos0, v0, q0 = log
    kw = {} if vset is None else {"velocity_set": vset}
    e, lib = build(tmp_path, algorithm="nav", structure=structure, subsamples=n, **kw)
    c, _, _ = _drive(e, lib, g, a, pos0, v0, q0)
    k = g.shape[0] // n * n if structure == "conventional" else g.shape[0]  # whole updates
    sol = navigate(g[:k], a[:k], n, h=H, lat=pos0[0], lon=pos0[1], height=pos0[2], v0=v0,
                   q0=q0, structure=structure, trailing="error", **kw)
    py = np.column_stack([sol.lat, sol.lon, sol.height, sol.v, sol.q])[1:]
    assert c.shape == py.shape
    scale = np.array([1.0, 1.0, 1e3, 1e2, 1e2, 1e2, 1.0, 1.0, 1.0, 1.0])  # rad, m, m/s, q
    err = np.max(np.abs(c - py) / scale)
    print(f"nav C {structure} N={n}: max |C - library| / scale {err:.1e}, "
          f"bit-identical rows {np.mean(np.all(c == py, axis=1)):.0%}")
    assert err <= 1e-13, err


def test_reset_restarts_and_the_code_is_allocation_free(tmp_path, log):
    g, a, pos0, v0, q0 = log
    e, lib = build(tmp_path, algorithm="nav", structure="conventional", subsamples=2)
    first, state, lib = _drive(e, lib, g[:400], a[:400], pos0, v0, q0)
    getattr(lib, f"{e.name}_reset")(state)
    dbl = ctypes.POINTER(ctypes.c_double)
    p, v, q = np.zeros(3), np.zeros(3), np.zeros(4)
    update = getattr(lib, f"{e.name}_update")
    for k in range(2):
        update(state, g[k].ctypes.data_as(dbl), a[k].ctypes.data_as(dbl), p.ctypes.data_as(dbl),
               v.ctypes.data_as(dbl), q.ctypes.data_as(dbl))
    assert np.array_equal(np.concatenate([p, v, q]), first[0])
    src = e.source + e.header
    assert "malloc" not in src and "free(" not in src and f"static {e.name}_real" not in src
    calls = set(re.findall(r"\b(sqrt|sin|cos|tan|exp|log|pow|atan2|fabs)\(", e.source))
    assert calls == {"sqrt", "sin", "cos"}
    assert "sculling 2/3" in e.source  # the two-sample sculling coefficient, exact form


def test_operation_counts():
    assert "nav" in ALGORITHMS
    one = nav_ops("conventional", 1)
    two = nav_ops("conventional", 2)
    # N = 2 adds one coning and one sculling pair (3 cross products) and 6 sums
    assert {k: two[k] - one[k] for k in one} == {"mul": 27, "add": 24, "div": 0, "sqrt": 0,
                                                  "sin": 0, "cos": 0, "tan": 0}
    assert one["tan"] == 0 and one["sin"] == 2 and one["cos"] == 2
    e = generate("nav", structure="single-chain", subsamples=3)
    assert f"mul {e.ops['mul']}" in e.header and e.ops == nav_ops("single-chain", 3)


@pytest.mark.parametrize(("kw", "msg"), [
    ({"structure": "realtime"}, "nav supports the structures conventional, single-chain"),
    ({"real": "float"}, "double only"),
    ({"coefficients": "miller"}, "designed coning and sculling sets only"),
    ({"subsamples": 7}, "N = 1 … 6, got N = 7"),
])
def test_bad_nav_export(tmp_path, kw, msg):
    with pytest.raises(ValueError, match=msg):
        export_c(tmp_path, algorithm="nav", **kw)


def test_default_and_classical_sets_differ_from_n_3_only():
    """N ≤ 2 has one velocity set (the C is the same text); from N = 3 the default pairs
    every two subsamples, the classical set only those with the last one."""
    for n in (1, 2):
        assert (generate("nav", subsamples=n).source
                == generate("nav", subsamples=n, velocity_set="classical").source)
    default = generate("nav", subsamples=3)
    classical = generate("nav", subsamples=3, velocity_set="classical")
    pairs = [len(re.findall(r"sd_cross_add\(dvb", e.source)) for e in (default, classical)]
    assert pairs == [6, 4]  # 3 pairs x 2 (theta_i x v_j and v_i x theta_j); 2 pairs x 2
    assert "coning-force" in default.header and "coning-force" not in classical.header
    with pytest.raises(ValueError, match="unknown velocity set"):
        generate("nav", subsamples=3, velocity_set="bogus")  # type: ignore[arg-type]
    with pytest.raises(ValueError, match="belongs to --algorithm nav"):
        generate("rotvec", velocity_set="classical")


def test_cli_writes_the_nav_code_and_rejects_a_sample_rate(tmp_path, capsys):
    from strapdown.cli import main

    assert main(["export-c", "--algorithm", "nav", "--structure", "single-chain",
                 "--subsamples", "2", "--out", str(tmp_path)]) == 0
    out = capsys.readouterr().out
    assert "sd_nav_single_chain_n2.c" in out and "tan 0" in out
    assert (tmp_path / "sd_nav_single_chain_n2.h").is_file()
    with pytest.raises(SystemExit) as exc:
        main(["export-c", "--algorithm", "nav", "--sample-rate-hz", "100", "--out",
              str(tmp_path / "x")])
    assert exc.value.code == 2 and "does not apply to nav" in capsys.readouterr().err
    assert not (tmp_path / "x").exists()
    assert main(["export-c", "--algorithm", "nav", "--velocity-set", "classical",
                 "--out", str(tmp_path / "cl")]) == 0
    assert (tmp_path / "cl" / "sd_nav_conventional_n3.c").read_text() == generate(
        "nav", velocity_set="classical").source
    with pytest.raises(SystemExit) as exc:
        main(["export-c", "--algorithm", "rotvec", "--velocity-set", "classical", "--out",
              str(tmp_path / "y")])
    assert exc.value.code == 2 and "belongs to --algorithm nav" in capsys.readouterr().err
