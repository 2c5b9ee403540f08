"""Generate self-contained, allocation-free C99 for a configured attitude algorithm.

``strapdown export-c --algorithm rotvec|rate-single|rate-three|rk4 ... --out DIR``
writes ``<name>.h`` and ``<name>.c``: a state struct, ``<name>_init``,
``<name>_reset`` and ``<name>_update`` (one increment or rate sample in; the
attitude quaternion out, return value 1, whenever an update completes). No
dynamic allocation; from libm only ``sqrt``, ``sin`` and ``cos``. Coefficients
are baked in as decimal literals with their exact rational form in a
comment. The C mirrors :mod:`strapdown.algorithms._kernels` operation by operation
(same small-angle series, same summation order), so in double precision it
matches the Python library to round-off.
"""

from __future__ import annotations

import re
from collections.abc import Callable
from dataclasses import dataclass
from fractions import Fraction
from pathlib import Path
from typing import Any, Literal, get_args

from strapdown._core.series import SMALL_ANGLE
from strapdown._core.validation import positive
from strapdown.algorithms.coning import CoefficientSet, coefficient_set
from strapdown.algorithms.family import Family, StructureName
from strapdown.algorithms.rate import Rk4, WindowedRateFamily
from strapdown.algorithms.rotvec import Rotvec
from strapdown.algorithms.spec import REGISTRY, AlgorithmName, AlgorithmSpec, CoefficientName
from strapdown.algorithms.velocity import DEFAULT_VELOCITY_SET, VelocitySet
from strapdown.codegen.nav_c import fill_names
from strapdown.io.files import write_text

__all__ = ["AHRS_ALGORITHMS", "ALGORITHMS", "ATTITUDE_ALGORITHMS", "NAV_ALGORITHMS", "REALS",
           "AhrsExportName", "CExport", "CReal", "ExportName", "NavExport", "export_c",
           "generate", "generate_coefficient_set"]

#: The C floating-point type of the generated code (``--float``).
CReal = Literal["double", "float"]
REALS: tuple[CReal, ...] = get_args(CReal)

@dataclass(frozen=True)
class CExport:
    """Generated source and its operation counts per update."""

    name: str
    header: str
    source: str
    ops: dict[str, int]
    real: CReal


def _lit(x, real) -> str:
    f = float(x)
    s = repr(f)
    if "e" not in s and "." not in s:
        s += ".0"
    return s + ("f" if real == "float" else "")


def _frac(x) -> str:
    if isinstance(x, Fraction):
        return f"{x.numerator}/{x.denominator}"
    return repr(float(x))


def _common(real: str) -> str:
    sq, sn, cs = ("sqrtf", "sinf", "cosf") if real == "float" else ("sqrt", "sin", "cos")
    s = _lit(SMALL_ANGLE, real)
    one = _lit(1.0, real)
    return f"""
/* q_out = normalise(qp (x) q(phi)); exact exponential map, sin/x and cos series below
   |phi|/2 < {SMALL_ANGLE} (truncation below 3e-22 relative) */
static void sd_update(const NAME_real qp[4], const NAME_real phi[3], NAME_real q_out[4])
{{
    NAME_real ang = {sq}(phi[0] * phi[0] + phi[1] * phi[1] + phi[2] * phi[2]);
    NAME_real half = {_lit(0.5, real)} * ang;
    NAME_real s, dw, dx, dy, dz, w, x, y, z, inv;
    if (half < {s}) {{
        NAME_real x2 = half * half;
        s = {_lit(0.5, real)} * ({one} - x2 / {_lit(6.0, real)}
            * ({one} - x2 / {_lit(20.0, real)} * ({one} - x2 / {_lit(42.0, real)})));
        dw = {one} - x2 / {_lit(2.0, real)} * ({one} - x2 / {_lit(12.0, real)}
            * ({one} - x2 / {_lit(30.0, real)} * ({one} - x2 / {_lit(56.0, real)})));
    }} else {{
        s = {sn}(half) / ang;
        dw = {cs}(half);
    }}
    dx = s * phi[0];
    dy = s * phi[1];
    dz = s * phi[2];
    w = qp[0] * dw - qp[1] * dx - qp[2] * dy - qp[3] * dz;
    x = qp[0] * dx + qp[1] * dw + qp[2] * dz - qp[3] * dy;
    y = qp[0] * dy - qp[1] * dz + qp[2] * dw + qp[3] * dx;
    z = qp[0] * dz + qp[1] * dy - qp[2] * dx + qp[3] * dw;
    inv = {one} / {sq}(w * w + x * x + y * y + z * z);
    q_out[0] = w * inv;
    q_out[1] = x * inv;
    q_out[2] = y * inv;
    q_out[3] = z * inv;
}}

static void sd_cross_add(NAME_real phi[3], NAME_real c, const NAME_real a[3], const NAME_real b[3])
{{
    phi[0] += c * (a[1] * b[2] - a[2] * b[1]);
    phi[1] += c * (a[2] * b[0] - a[0] * b[2]);
    phi[2] += c * (a[0] * b[1] - a[1] * b[0]);
}}

/* phi += c m x (a x b): a triple cross product (finite-amplitude sets) */
static void sd_triple_add(NAME_real phi[3], NAME_real c, const NAME_real m[3], const NAME_real a[3],
                          const NAME_real b[3])
{{
    NAME_real u[3];
    u[0] = a[1] * b[2] - a[2] * b[1];
    u[1] = a[2] * b[0] - a[0] * b[2];
    u[2] = a[0] * b[1] - a[1] * b[0];
    sd_cross_add(phi, c, m, u);
}}
"""


#: sd_update on its sin/cos branch, counted from the generated code: |φ| (3 mul, 2 add,
#: sqrt), half (1 mul), sin/ang (div), 3 mul, quaternion product (16 mul, 12 add),
#: normalisation (4 mul, 3 add, sqrt, div, 4 mul). Below the small-angle threshold
#: (|φ|/2 < 1e-2) sin and cos are replaced by their series (no libm call).
_UPDATE_OPS = {"mul": 31, "add": 17, "div": 2, "sqrt": 2, "sin": 1, "cos": 1}
_CROSS_OPS = {"mul": 9, "add": 6}
#: sd_triple_add: the inner cross product (6 mul, 3 add) and sd_cross_add.
_TRIPLE_OPS = {"mul": 15, "add": 9}


def _add_ops(*parts):
    out = {}
    for p in parts:
        for k, v in p.items():
            out[k] = out.get(k, 0) + v
    return out


def _times(d, n):
    return {k: v * n for k, v in d.items()}


def _init_reset(first_q: str, counter: str) -> str:
    """C ``init`` (store q0 in ``s->q0`` and ``s->{first_q}``, zero the counter) and ``reset``."""
    return f"""
void NAME_init(NAME_state *s, const NAME_real q0[4])
{{
    int i;
    for (i = 0; i < 4; ++i) {{ s->q0[i] = q0[i]; s->{first_q}[i] = q0[i]; }}
    s->{counter} = 0;
}}

void NAME_reset(NAME_state *s) {{ NAME_init(s, s->q0); }}
"""


def _rotvec_terms(k) -> list[tuple[int, int, object]]:
    n = len(k)
    return [(i, j, k[i][j]) for i in range(n) for j in range(i + 1, n) if k[i][j] != 0]


def _phi_rotvec(terms, src, base_expr, n, real, comment=True):
    lines = ["    phi[0] = 0; phi[1] = 0; phi[2] = 0;"]
    for i in range(n):
        lines.append(f"    phi[0] += {src}[{base_expr(i)}][0]; phi[1] += {src}[{base_expr(i)}][1]; "
                     f"phi[2] += {src}[{base_expr(i)}][2];")
    for i, j, c in terms:
        cmt = f" /* {_frac(c)} */" if comment else ""
        lines.append(f"    sd_cross_add(phi, {_lit(c, real)}{cmt}, {src}[{base_expr(i)}], "
                     f"{src}[{base_expr(j)}]);")
    return "\n".join(lines)


def _triple_lines(triples, src, base_expr, real):
    """``sd_triple_add`` per triple term ``(m, i, j, τ)``, in the kernels' order
    (:func:`strapdown.algorithms._kernels._add_triples`)."""
    return "\n".join(
        f"    sd_triple_add(phi, {_lit(c, real)} /* {_frac(c)} */, {src}[{base_expr(m)}], "
        f"{src}[{base_expr(i)}], {src}[{base_expr(j)}]);" for m, i, j, c in triples)


def _generate_nav(structure: StructureName, subsamples: int,
                  coefficients: CoefficientName | None, real: CReal,
                  name: str | None, velocity_set: VelocitySet) -> CExport:
    """The navigation update (:mod:`strapdown.codegen.nav_c`)."""
    from strapdown.codegen.nav_c import generate_nav

    designed = Rotvec.default_coefficients  # the coning set the velocity update runs
    if coefficients not in (None, designed):
        raise ValueError(f"nav exports the designed coning and sculling sets only ({designed})")
    if real != "double":
        raise ValueError("nav is exported in double only: a float latitude resolves 0.6 m")
    name = name or f"sd_nav_{structure.replace('-', '_')}_n{subsamples}"
    if not re.fullmatch(r"[A-Za-z_][A-Za-z0-9_]*", name):
        raise ValueError(f"name must be a C identifier, got {name!r}")
    common = _common("double")
    common = common[:common.index("\n/* phi += c m x (a x b)")]  # nav has no triple terms
    header, source, ops = generate_nav(structure, subsamples, name, common, velocity_set)
    return CExport(name, header, source, ops, real)


def generate(algorithm: ExportName, *, structure: StructureName = "conventional",
             subsamples: int = 3, coefficients: CoefficientName | None = None,
             real: CReal = "double", h: float = 1e-4, name: str | None = None,
             velocity_set: VelocitySet = DEFAULT_VELOCITY_SET) -> CExport:
    """Generate the C for one configuration (see :func:`export_c`).

    ``algorithm="nav"``: the navigation update on the WGS-84 Earth with coning and sculling
    compensation (:mod:`strapdown.codegen.nav_c`; its sample interval is an argument of the
    generated init, ``h`` here is not used), with the conventional structure's sculling
    pairs ``velocity_set`` (the library's default, as ``strapdown nav`` runs; the single
    chain has one set). The attitude algorithms take no velocity set.
    """
    if algorithm == "nav":
        return _generate_nav(structure, subsamples, coefficients, real, name, velocity_set)
    if velocity_set != DEFAULT_VELOCITY_SET:
        raise ValueError("--velocity-set belongs to --algorithm nav")
    if algorithm == "ahrs":
        raise ValueError("the AHRS has its own generator: strapdown.codegen.ahrs_c.generate_ahrs")
    if algorithm not in _GENERATORS:
        raise ValueError(f"unknown algorithm {algorithm!r}; choose one of {', '.join(ALGORITHMS)}")
    spec = AlgorithmSpec(algorithm, structure=structure, subsamples=subsamples,
                         coefficients=coefficients)
    if real not in REALS:
        raise ValueError(f"--float must be double or float, got {real!r}")
    h = positive(h, "h (sample interval)")
    fam = spec.family
    name = name or re.sub(r"[^a-z0-9]+", "_", f"sd_{algorithm}_{structure}"
                          + (f"_n{subsamples}" if "subsamples" in fam.options else "")
                          ).strip("_")
    if not re.fullmatch(r"[A-Za-z_][A-Za-z0-9_]*", name):
        raise ValueError(f"name must be a C identifier, got {name!r}")
    return _assemble(fam.input_kind == "increment", isinstance(fam, Rk4), fam.reference, name,
                     real, h, _GENERATORS[algorithm](spec, real, h))


def generate_coefficient_set(coefficients: CoefficientSet, *, real: CReal = "double",
                             name: str | None = None) -> CExport:
    """The C of the conventional rotation-vector update with any coefficient set — pair and
    triple terms, e.g. a designed one (:meth:`strapdown.design.Design.coefficient_set`, such
    as :func:`strapdown.design.finite_amplitude.derive_triple_a6`'s) — written like the
    named sets of :func:`generate`."""
    if not isinstance(coefficients, CoefficientSet):
        raise ValueError("coefficients must be a CoefficientSet")
    if real not in REALS:
        raise ValueError(f"--float must be double or float, got {real!r}")
    name = name or re.sub(r"[^a-z0-9]+", "_", f"sd_rotvec_{coefficients.name}_n"
                          f"{coefficients.n}").strip("_")
    if not re.fullmatch(r"[A-Za-z_][A-Za-z0-9_]*", name):
        raise ValueError(f"name must be a C identifier, got {name!r}")
    return _assemble(True, False, REGISTRY["rotvec"].reference, name, real, 1.0,
                     _gen_conventional(coefficients, real))


def _assemble(increments: bool, rk4: bool, reference: str, name: str, real: CReal, h: float,
              generated: tuple[str, str, dict[str, int], str]) -> CExport:
    """Header and source around a generator's state struct, body, op counts and description."""
    struct, body, ops, info = generated
    guard = name.upper() + "_H"
    header = f"""/* {name}.h — generated by strapdown export-c. Do not edit.
 * Algorithm: {info}
 * Reference: {reference}
 * Real type: {real}. Input: {"angular increments (rad)" if increments else
                              f"angular rates (rad/s) sampled every {h!r} s"}.
 * Convention: Hamilton quaternions, scalar first, q_n_b (body to reference).
 * Operations per update: {", ".join(f"{k} {v}" for k, v in ops.items())}.
 */
#ifndef {guard}
#define {guard}

typedef {real} {name}_real;

typedef struct {{
{fill_names(struct, name)}
}} {name}_state;

/* sizeof({name}_state), for callers through a foreign-function interface. */
unsigned long {name}_state_size(void);
/* Initialise with the attitude q0 (scalar first) at the first sample. */
void {name}_init({name}_state *s, const {name}_real q0[4]);
/* Back to the state right after init (same q0). */
void {name}_reset({name}_state *s);
/* Feed one sample; returns 1 and writes q_out when an attitude update completes. */
int {name}_update({name}_state *s, const {name}_real sample[3], {name}_real q_out[4]);

#endif
"""
    common = _common(real)
    cross = common.index("static void sd_cross_add")
    triple = common.index("\n/* phi += c m x (a x b)")
    helpers = ("" if rk4 else common[:cross]) + (
        common[cross:triple] if "sd_cross_add" in body or "sd_triple_add" in body else "") + (
        common[triple:] if "sd_triple_add" in body else "")
    source = f"""/* {name}.c — generated by strapdown export-c. Do not edit. See {name}.h. */
#include <math.h>
#include "{name}.h"
{fill_names(helpers, name)}
unsigned long {name}_state_size(void) {{ return (unsigned long)sizeof({name}_state); }}
{fill_names(body, name)}
"""
    return CExport(name, header, source, ops, real)


def _gen_rotvec(spec, real, h):
    st = spec.update_structure
    cs = coefficient_set(spec.coefficients or spec.family.default_coefficients,
                         spec.subsamples)
    if st.own_startup:  # the single chain: its designed coefficients, with their triples
        try:
            designed = st.chain_subsamples(cs) == cs.n  # not the plain sum
        except ValueError:
            designed = False
        if not designed:
            raise ValueError("the single chain exports its designed coefficients only "
                             "(table3 or finite-amplitude)")
        return _gen_single_chain(spec.subsamples, real, st.triple(cs))
    if cs.triples and st.pair_only:
        raise ValueError(f"{cs.name!r} has triple cross products, which run in the "
                         "conventional and single-chain structures only")
    if st.interleaved:
        return _gen_realtime(cs, real)
    return _gen_conventional(cs, real)


def _gen_single_chain(n, real, triple=False):
    """Single chain: one update per increment, cross products with the previous N − 1
    (``triple``: the finite-amplitude triple terms once N − 1 previous increments exist,
    as :func:`strapdown.algorithms.structures.single_chain`)."""
    from strapdown.algorithms.finite_amplitude import triple_terms
    from strapdown.algorithms.structures import single_chain_coefficients

    rows = [list(single_chain_coefficients(m + 1)) for m in range(n)]
    width = max(n - 1, 1)
    table = ",\n".join("    {" + ", ".join(
        [f"{_lit(c, real)} /* {_frac(c)} */" for c in r]
        + [_lit(0, real)] * (width - len(r))) + "}" for r in rows)
    struct = (f"    NAME_real q[4];\n    NAME_real q0[4];\n    NAME_real hist[{width}][3];\n"
              "    long k;")
    tri = triple_terms("single-chain", n) if triple else ()
    tri_code = ""
    if tri:  # node N − 1 is the new increment, node l < N − 1 the one N − 1 − l before it
        win = ", ".join(f"s->hist[(s->k - {n - 1 - node}) % {width}]" for node in range(n - 1))
        tri_code = (f"\n    if (m == {n - 1}) {{\n"
                    f"        const NAME_real *w[{n}] = {{{win}, th}};\n"
                    + "\n".join("    " + ln for ln in _triple_lines(
                        tri, "w", str, real).splitlines()) + "\n    }")
    body = f"""
static const NAME_real SC[{n}][{width}] = {{
{table}
}};
{_init_reset("q", "k")}

int NAME_update(NAME_state *s, const NAME_real th[3], NAME_real q_out[4])
{{
    NAME_real phi[3];
    int m = (int)(s->k < {n - 1} ? s->k : {n - 1});
    int p, i;
    phi[0] = th[0]; phi[1] = th[1]; phi[2] = th[2];
    for (p = 1; p <= m; ++p) {{
        const NAME_real *a = s->hist[(s->k - p) % {width}];
        if (SC[m][p - 1] != 0) sd_cross_add(phi, SC[m][p - 1], a, th);
    }}{tri_code}
    sd_update(s->q, phi, q_out);
    for (i = 0; i < 4; ++i) s->q[i] = q_out[i];
    for (i = 0; i < 3; ++i) s->hist[s->k % {width}][i] = th[i];
    s->k += 1;
    return 1;
}}
"""
    ops = _add_ops(_times(_CROSS_OPS, n - 1), _times(_TRIPLE_OPS, len(tri)), _UPDATE_OPS)
    return struct, body, ops, (f"single-chain rotation vector, N = {n}, "
                               + ("finite-amplitude (triple terms), " if tri else "")
                               + "update every h")


def _gen_conventional(cs, real):
    """Conventional structure: an update every N increments."""
    n = cs.n
    k = cs.exact if cs.exact is not None else cs.matrix.tolist()
    terms = _rotvec_terms(k)
    struct = f"    NAME_real q[4];\n    NAME_real q0[4];\n    NAME_real th[{n}][3];\n    int count;"
    phi = _phi_rotvec(terms, "s->th", lambda i: str(i), n, real)
    if cs.triples:
        phi += "\n" + _triple_lines(cs.triples, "s->th", str, real)
    body = f"""{_init_reset("q", "count")}

int NAME_update(NAME_state *s, const NAME_real sample[3], NAME_real q_out[4])
{{
    NAME_real phi[3];
    int i;
    for (i = 0; i < 3; ++i) s->th[s->count][i] = sample[i];
    s->count += 1;
    if (s->count < {n}) return 0;
    s->count = 0;
{phi}
    sd_update(s->q, phi, q_out);
    for (i = 0; i < 4; ++i) s->q[i] = q_out[i];
    return 1;
}}
"""
    ops = _add_ops({"add": 3 * n}, _times(_CROSS_OPS, len(terms)),
                   _times(_TRIPLE_OPS, len(cs.triples)), _UPDATE_OPS)
    return struct, body, ops, (f"rotation vector, N = {n}, coefficients {cs.name}, "
                               "conventional structure (update every N h)")


def _gen_realtime(cs, real):
    """Real-time structure: a ring of the last N increments and N attitudes."""
    from strapdown.algorithms.structures import startup_sets

    n = cs.n
    terms = _rotvec_terms(cs.exact if cs.exact is not None else cs.matrix.tolist())
    sets = startup_sets(cs)
    starts = []
    for m, st in enumerate(sets[:-1], start=1):
        km = st.exact if st.exact is not None else st.matrix.tolist()
        phi_m = _phi_rotvec(_rotvec_terms(km), "s->th", lambda i: str(i), m, real)
        starts.append(f"    if (s->k == {m}) {{\n{phi_m}\n        sd_update(s->q0, phi, q_out);"
                      f"\n    }}")
    main_phi = _phi_rotvec(terms, "s->th", lambda i: f"(s->k - {n} + {i}) % {n}", n, real)
    struct = (f"    NAME_real qh[{n}][4];\n    NAME_real q0[4];\n    NAME_real th[{n}][3];\n"
              "    long k;")
    body = f"""{_init_reset("qh[0]", "k")}

int NAME_update(NAME_state *s, const NAME_real sample[3], NAME_real q_out[4])
{{
    NAME_real phi[3];
    int i;
    for (i = 0; i < 3; ++i) s->th[s->k % {n}][i] = sample[i];
    s->k += 1;
    if (s->k < {n}) {{
{chr(10).join(starts) if starts else ""}
    }} else {{
{main_phi}
        sd_update(s->qh[(s->k - {n}) % {n}], phi, q_out);
    }}
    for (i = 0; i < 4; ++i) s->qh[s->k % {n}][i] = q_out[i];
    return 1;
}}
"""
    ops = _add_ops({"add": 3 * n}, _times(_CROSS_OPS, len(terms)), _UPDATE_OPS)
    return struct, body, ops, (f"rotation vector, N = {n}, coefficients {cs.name}, Li & Zhang "
                               "real-time structure (update every h, N interleaved chains)")


def _gen_rate(spec, real, h):
    from strapdown.algorithms import rate

    algorithm, structure = spec.algorithm, spec.structure
    single = rate.single_period_algorithm(spec.resolved_coefficients)
    alg = spec.family.windowed(spec)
    w = len(alg.offsets)

    def phi_code(a, idx):
        lines = ["    phi[0] = 0; phi[1] = 0; phi[2] = 0;"]
        for i, wt in enumerate(a.weights):
            sw = h * float(wt)
            lines.append(f"    phi[0] += {_lit(sw, real)} * PREFIX_W({idx(i)})[0]; phi[1] += "
                         f"{_lit(sw, real)} * PREFIX_W({idx(i)})[1]; phi[2] += {_lit(sw, real)} * "
                         f"PREFIX_W({idx(i)})[2]; /* h * {_frac(wt)} */")
        for (i, j), c in zip(a.pairs, a.pair_coefficients, strict=True):
            lines.append(f"    sd_cross_add(phi, {_lit(h * h * float(c), real)} /* h^2 * "
                         f"{_frac(c)} */, PREFIX_W({idx(i)}), PREFIX_W({idx(j)}));")
        return "\n".join(lines)

    u = alg.update
    ring = w + 1
    struct = (f"    NAME_real qh[{u}][4];\n    NAME_real q0[4];\n    NAME_real win[{ring}][3];\n"
              "    long k;")
    macro = f"#define PREFIX_W(i) (s->win[((i) % {ring} + {ring}) % {ring}])"
    sliding = spec.update_structure.interleaved  # the sliding scheme, started single-period
    if not sliding:
        body_update = f"""
    /* sample index j = s->k - 1 just stored; an update completes every {u} samples */
    if (s->k - 1 < {u} || (s->k - 1) % {u} != 0) return 0;
    {{
        long b = s->k - 1 - {u};
{phi_code(alg, lambda i: f"b + {alg.offsets[i]}")}
        sd_update(s->qh[0], phi, q_out);
        for (i = 0; i < 4; ++i) s->qh[0][i] = q_out[i];
    }}
    return 1;"""
        ops = _add_ops(_times({"mul": 3, "add": 3}, len(alg.weights)),
                       _times(_CROSS_OPS, len(alg.pairs)), _UPDATE_OPS)
    else:
        body_update = f"""
    {{
        long j = s->k - 1;  /* newest sample index */
        if (j == 0) return 0;
        if (j < {u}) {{
            long b = j - 1;
{phi_code(single, lambda i: f"b + {single.offsets[i]}")}
            sd_update(s->qh[(j - 1) % {u}], phi, q_out);
        }} else {{
            long b = j - {u};
{phi_code(alg, lambda i: f"b + {alg.offsets[i]}")}
            sd_update(s->qh[b % {u}], phi, q_out);
        }}
        for (i = 0; i < 4; ++i) s->qh[j % {u}][i] = q_out[i];
    }}
    return 1;"""
        ops = _add_ops(_times({"mul": 3, "add": 3}, len(alg.weights)),
                       _times(_CROSS_OPS, len(alg.pairs)), _UPDATE_OPS)
    body = f"""
{macro}
{_init_reset("qh[0]", "k")}

int NAME_update(NAME_state *s, const NAME_real sample[3], NAME_real q_out[4])
{{
    NAME_real phi[3];
    int i;
    for (i = 0; i < 3; ++i) PREFIX_W(s->k)[i] = sample[i];
    s->k += 1;
    (void)phi;
{body_update}
}}
"""
    info = (f"{algorithm}, coefficients {spec.resolved_coefficients}, {structure} structure, "
            f"td = {h!r} s")
    return struct, body, ops, info


def _gen_rk4(spec, real, h):
    if spec.rk4_step != "2td":
        raise ValueError("the exported rk4 is the 2td step")
    sq = "sqrtf" if real == "float" else "sqrt"
    big_h = 2 * h
    struct = "    NAME_real q[4];\n    NAME_real q0[4];\n    NAME_real w[3][3];\n    long k;"
    body = f"""
static void f(const NAME_real q[4], const NAME_real *w, NAME_real out[4])
{{
    out[0] = {_lit(0.5, real)} * (-q[1] * w[0] - q[2] * w[1] - q[3] * w[2]);
    out[1] = {_lit(0.5, real)} * (q[0] * w[0] + q[2] * w[2] - q[3] * w[1]);
    out[2] = {_lit(0.5, real)} * (q[0] * w[1] - q[1] * w[2] + q[3] * w[0]);
    out[3] = {_lit(0.5, real)} * (q[0] * w[2] + q[1] * w[1] - q[2] * w[0]);
}}
{_init_reset("q", "k")}

int NAME_update(NAME_state *s, const NAME_real sample[3], NAME_real q_out[4])
{{
    NAME_real k1[4], k2[4], k3[4], k4[4], tmp[4], n2 = 0;
    int i;
    const NAME_real H = {_lit(big_h, real)};
    for (i = 0; i < 3; ++i) s->w[s->k % 3][i] = sample[i];
    s->k += 1;
    if (s->k < 3 || (s->k - 1) % 2 != 0) return 0;
    {{
        const NAME_real *w0 = s->w[(s->k - 3) % 3], *wm = s->w[(s->k - 2) % 3],
                     *w1 = s->w[(s->k - 1) % 3];
        f(s->q, w0, k1);
        for (i = 0; i < 4; ++i) tmp[i] = s->q[i] + {_lit(0.5, real)} * H * k1[i];
        f(tmp, wm, k2);
        for (i = 0; i < 4; ++i) tmp[i] = s->q[i] + {_lit(0.5, real)} * H * k2[i];
        f(tmp, wm, k3);
        for (i = 0; i < 4; ++i) tmp[i] = s->q[i] + H * k3[i];
        f(tmp, w1, k4);
        for (i = 0; i < 4; ++i) {{
            tmp[i] = s->q[i] + H / {_lit(6.0, real)}
                * (k1[i] + {_lit(2.0, real)} * k2[i] + {_lit(2.0, real)} * k3[i] + k4[i]);
            n2 += tmp[i] * tmp[i];
        }}
        n2 = {_lit(1.0, real)} / {sq}(n2);
        for (i = 0; i < 4; ++i) {{ s->q[i] = tmp[i] * n2; q_out[i] = s->q[i]; }}
    }}
    return 1;
}}
"""
    # counted from the code below: 4 × f (16 mul, 12 add), the three intermediate states
    # (8 + 8 + 4 mul, 12 add), the final combination (4 div, 12 mul, 16 add), norm (4 mul,
    # 4 add, sqrt, div) and scaling (4 mul)
    ops = {"mul": 104, "add": 80, "div": 5, "sqrt": 1, "sin": 0, "cos": 0}
    return struct, body, ops, f"quaternion RK4, step 2 td, td = {h!r} s"


_Generator = Callable[[AlgorithmSpec, CReal, float], tuple[str, str, dict[str, int], str]]


def _generator(family: Family) -> _Generator | None:
    """The C template for a family (the templates are the exporter's own knowledge): the
    rotation vector, RK4, and every windowed rate family through one template."""
    if isinstance(family, Rotvec):
        return _gen_rotvec
    if isinstance(family, Rk4):
        return _gen_rk4
    if isinstance(family, WindowedRateFamily):
        return _gen_rate
    return None


#: C generator per exportable family, in registry order.
_GENERATORS: dict[AlgorithmName, _Generator] = {
    name: g for name, fam in REGISTRY.items() if (g := _generator(fam)) is not None}
#: Attitude families ``export-c`` can generate, in registry order.
ATTITUDE_ALGORITHMS: tuple[AlgorithmName, ...] = tuple(_GENERATORS)
#: What ``export-c`` generates besides attitude: the navigation update with sculling.
NavExport = Literal["nav"]
NAV_ALGORITHMS: tuple[NavExport, ...] = get_args(NavExport)
#: The AHRS filter, generated by :mod:`strapdown.codegen.ahrs_c` (its own options).
AhrsExportName = Literal["ahrs"]
AHRS_ALGORITHMS: tuple[AhrsExportName, ...] = get_args(AhrsExportName)
#: Everything ``export-c --algorithm`` takes: the attitude families, ``nav``, ``ahrs``.
ExportName = AlgorithmName | NavExport | AhrsExportName
ALGORITHMS: tuple[ExportName, ...] = (*ATTITUDE_ALGORITHMS, *NAV_ALGORITHMS, *AHRS_ALGORITHMS)


def export_c(out: str | Path, **kwargs: Any) -> CExport:
    """Generate and write ``<name>.h`` and ``<name>.c`` into ``out`` (atomically)."""
    exp = generate(**kwargs)
    out = Path(out)
    if out.exists() and not out.is_dir():
        raise ValueError(f"--out {out} exists and is not a directory")
    write_text(out / f"{exp.name}.h", exp.header)
    write_text(out / f"{exp.name}.c", exp.source)
    return exp
