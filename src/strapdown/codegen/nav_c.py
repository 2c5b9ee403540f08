"""C99 for the navigation update on the WGS-84 Earth: coning, rotation and sculling
compensated body increments, then velocity, position and attitude in NED.

``strapdown export-c --algorithm nav --structure conventional|single-chain --subsamples N``
writes ``<name>.h`` and ``<name>.c``: a state struct, ``<name>_init`` (sample interval,
initial latitude, longitude, height, NED velocity and ``q_n_b``), ``<name>_reset`` and
``<name>_update`` (one gyro increment in rad and one accelerometer increment in m/s in;
position, velocity and attitude out, return value 1, whenever an update completes). No
dynamic allocation; from libm ``sqrt``, ``sin`` and ``cos``. The code mirrors
:func:`strapdown.algorithms._velocity_kernels.conventional_body_kernel` /
:func:`~strapdown.algorithms._velocity_kernels.single_chain_body_kernel` and
:func:`strapdown.navigation._kernels.earth_nav_chunk_kernel` operation by operation
(Savage (1998b); the sculling coefficients of the designer's sculling target, which are
the coning ones, Ignagni (1998)); the position increment ``ΔR_b`` of the scrolling
compensation is not part of it, as the Earth navigation integrates position by the
Adams–Moulton rules of the position rates at the updates (see
:mod:`strapdown.navigation.earth`). Double precision only: a float latitude resolves
0.6 m.
"""

from __future__ import annotations

import re
from fractions import Fraction
from pathlib import Path

from strapdown.algorithms import tables
from strapdown.algorithms.coning import coefficient_set
from strapdown.algorithms.structures import (
    STRUCTURE_REGISTRY,
    UpdateStructure,
    single_chain_coefficients,
)
from strapdown.algorithms.velocity import (
    DEFAULT_VELOCITY_SET,
    VelocitySet,
    effective_velocity_set,
    nav_structures,
    sculling_matrix,
)
from strapdown.navigation import _kernels as nk

__all__ = ["fill_names", "generate_nav", "nav_ops"]

#: The C templates beside this module (the navigation step: ``nav_step.c.in``).
_TEMPLATES = Path(__file__).parent / "templates"


def _lit(x) -> str:
    s = repr(float(x))
    return s if ("e" in s or "." in s or "n" in s) else s + ".0"


def _frac(x) -> str:
    return f"{x.numerator}/{x.denominator}" if isinstance(x, Fraction) else repr(float(x))


_CONSTANTS = {"PREFIX_A": nk._A, "PREFIX_F": nk._F, "PREFIX_E2": nk._E2, "PREFIX_OMEGA": nk._OMEGA,
              "PREFIX_GE": nk._GE, "PREFIX_GK": nk._GK, "PREFIX_GM": nk._GM_RATIO}


def fill_names(text: str, name: str) -> str:
    """A template with its placeholders filled in one pass: ``NAME`` by the module name (its
    functions and types, e.g. ``NAME_real``, ``NAME_state``), ``PREFIX_`` by the upper-case
    name and ``_`` (its macros), so every generated type and macro carries the prefix."""
    return re.sub(r"NAME|PREFIX_", lambda m: name if m.group() == "NAME"
                  else name.upper() + "_", text)


def _helpers() -> str:
    """The small functions of the velocity and navigation kernels, in C."""
    consts = "\n".join(f"#define {k} {_lit(v)}" for k, v in _CONSTANTS.items())
    return f"""
/* WGS-84 (NIMA TR8350.2 (2000)): semi-major axis, flattening, e^2, Earth rate, Somigliana */
{consts}

static void sd_cross(const NAME_real a[3], const NAME_real b[3], NAME_real out[3])
{{
    out[0] = a[1] * b[2] - a[2] * b[1];
    out[1] = a[2] * b[0] - a[0] * b[2];
    out[2] = a[0] * b[1] - a[1] * b[0];
}}

/* out = v + 1/2 a x v + 1/6 a x (a x v): rotation compensation to second order */
static void sd_rotation_comp(const NAME_real a[3], const NAME_real u[3], NAME_real out[3])
{{
    NAME_real cx = a[1] * u[2] - a[2] * u[1];
    NAME_real cy = a[2] * u[0] - a[0] * u[2];
    NAME_real cz = a[0] * u[1] - a[1] * u[0];
    out[0] = u[0] + 0.5 * cx + (a[1] * cz - a[2] * cy) / 6.0;
    out[1] = u[1] + 0.5 * cy + (a[2] * cx - a[0] * cz) / 6.0;
    out[2] = u[2] + 0.5 * cz + (a[0] * cy - a[1] * cx) / 6.0;
}}

/* out = C(q) x */
static void sd_rotate(const NAME_real q[4], const NAME_real x[3], NAME_real out[3])
{{
    NAME_real tx = 2.0 * (q[2] * x[2] - q[3] * x[1]);
    NAME_real ty = 2.0 * (q[3] * x[0] - q[1] * x[2]);
    NAME_real tz = 2.0 * (q[1] * x[1] - q[2] * x[0]);
    out[0] = x[0] + q[0] * tx + (q[2] * tz - q[3] * ty);
    out[1] = x[1] + q[0] * ty + (q[3] * tx - q[1] * tz);
    out[2] = x[2] + q[0] * tz + (q[1] * ty - q[2] * tx);
}}

/* out = normalise(q(z) (x) q), exact exponential, series below |z|/2 < 1e-2 */
static void sd_left_update(const NAME_real z[3], const NAME_real q[4], NAME_real out[4])
{{
    NAME_real ang = sqrt(z[0] * z[0] + z[1] * z[1] + z[2] * z[2]);
    NAME_real half = 0.5 * ang, s, dw, dx, dy, dz, w, x, y, zz, inv;
    if (half < 1e-2) {{
        NAME_real x2 = half * half;
        s = 0.5 * (1.0 - x2 / 6.0 * (1.0 - x2 / 20.0 * (1.0 - x2 / 42.0)));
        dw = 1.0 - x2 / 2.0 * (1.0 - x2 / 12.0 * (1.0 - x2 / 30.0 * (1.0 - x2 / 56.0)));
    }} else {{
        s = sin(half) / ang;
        dw = cos(half);
    }}
    dx = s * z[0];
    dy = s * z[1];
    dz = s * z[2];
    w = dw * q[0] - dx * q[1] - dy * q[2] - dz * q[3];
    x = dw * q[1] + dx * q[0] + dy * q[3] - dz * q[2];
    y = dw * q[2] - dx * q[3] + dy * q[0] + dz * q[1];
    zz = dw * q[3] + dx * q[2] - dy * q[1] + dz * q[0];
    inv = 1.0 / sqrt(w * w + x * x + y * y + zz * zz);
    out[0] = w * inv;
    out[1] = x * inv;
    out[2] = y * inv;
    out[3] = zz * inv;
}}
"""


def _step() -> str:
    """One navigation update from body increments (``earth_nav_chunk_kernel``'s loop body):
    ``templates/nav_step.c.in``."""
    return "\n" + (_TEMPLATES / "nav_step.c.in").read_text(encoding="utf-8")


def _cross_terms(matrix, exact, sym: str, a: str, b: str, out: str, twin: bool) -> list[str]:
    """``sd_cross_add`` lines for the nonzero ``matrix[i][j]`` (i < j), exact form in a comment;
    ``twin`` adds the sculling pair's mirror ``b_i × a_j``."""
    lines = []
    n = len(matrix)
    for i in range(n - 1):
        for j in range(i + 1, n):
            if matrix[i][j] != 0:
                c = f"{_lit(matrix[i][j])} /* {sym} {_frac(exact[i][j])} */"
                lines.append(f"    sd_cross_add({out}, {c}, {a}[{i}], {b}[{j}]);")
                if twin:
                    lines.append(f"    sd_cross_add({out}, {c}, {b}[{i}], {a}[{j}]);")
    return lines


def _conventional(n: int, velocity_set: VelocitySet = DEFAULT_VELOCITY_SET
                  ) -> tuple[str, str, dict[str, int]]:
    """State fields and update of the conventional structure: an update every N samples,
    with the sculling pairs of ``velocity_set`` (:func:`~strapdown.algorithms.velocity.
    sculling_matrix`)."""
    cs = coefficient_set("table3", n)
    kc, kx = cs.matrix.tolist(), cs.exact
    sx = sculling_matrix(n, exact=True, velocity_set=velocity_set)
    ks = [[float(v) for v in r] for r in sx]
    # the kernel interleaves the coning and sculling terms per pair; they feed different
    # sums, so the order within each sum (i outer, j inner) is what is kept
    coning = _cross_terms(kc, kx, "coning", "s->th", "s->th", "phi", False)
    scul = _cross_terms(ks, sx, "sculling", "s->th", "s->dv", "dvb", True)
    fields = f"    NAME_real th[{n}][3];\n    NAME_real dv[{n}][3];\n    int count;"
    body = f"""
int NAME_update(NAME_state *s, const NAME_real dth[3], const NAME_real dv[3], NAME_real pos[3],
                NAME_real vel[3], NAME_real q[4])
{{
    NAME_real alpha[3] = {{0.0, 0.0, 0.0}}, ups[3] = {{0.0, 0.0, 0.0}}, phi[3], dvb[3];
    int i, j;
    for (i = 0; i < 3; ++i) {{ s->th[s->count][i] = dth[i]; s->dv[s->count][i] = dv[i]; }}
    s->count += 1;
    if (s->count < {n}) return 0;
    s->count = 0;
    for (j = 0; j < {n}; ++j)
        for (i = 0; i < 3; ++i) {{ alpha[i] += s->th[j][i]; ups[i] += s->dv[j][i]; }}
    for (i = 0; i < 3; ++i) phi[i] = alpha[i];
    sd_rotation_comp(alpha, ups, dvb);
{chr(10).join(coning + scul)}
    sd_nav_step(s, phi, dvb);
    for (i = 0; i < 3; ++i) {{ pos[i] = s->pos[i]; vel[i] = s->v[i]; }}
    for (i = 0; i < 4; ++i) q[i] = s->q[i];
    return 1;
}}
"""
    ops = _sum(_times(_CROSS, len(coning) + len(scul)), {"add": 6 * n}, _ROTATION_COMP,
               _STEP, _UPDATE)
    return fields, body, ops


def _single_chain(n: int) -> tuple[str, str, dict[str, int]]:
    """State fields and update of the single chain: an update every sample."""
    width = max(n - 1, 1)

    def table(rows):
        return ",\n".join("    {" + ", ".join(
            [f"{_lit(c)} /* {_frac(c)} */" for c in r] + ["0.0"] * (width - len(r))) + "}"
            for r in rows)

    coning = [list(single_chain_coefficients(m + 1)) if m else [] for m in range(n)]
    scul = [list(tables.SCULLING_SINGLE_CHAIN[m + 1]) if m else [] for m in range(n)]
    fields = (f"    NAME_real th[{width}][3];\n    NAME_real dv[{width}][3];\n    long k;")
    body = f"""
static const NAME_real SC_CONING[{n}][{width}] = {{
{table(coning)}
}};
static const NAME_real SC_SCULLING[{n}][{width}] = {{
{table(scul)}
}};

int NAME_update(NAME_state *s, const NAME_real dth[3], const NAME_real dv[3], NAME_real pos[3],
                NAME_real vel[3], NAME_real q[4])
{{
    NAME_real phi[3], dvb[3];
    int row = (int)(s->k < {n - 1} ? s->k : {n - 1}), m, i;
    for (i = 0; i < 3; ++i) phi[i] = dth[i];
    sd_rotation_comp(dth, dv, dvb);
    for (m = 1; m <= row; ++m) {{
        const NAME_real *tp = s->th[(s->k - m) % {width}], *vp = s->dv[(s->k - m) % {width}];
        NAME_real cc = SC_CONING[row][m - 1], cs = SC_SCULLING[row][m - 1];
        if (cc != 0.0) sd_cross_add(phi, cc, tp, dth);
        if (cs != 0.0) {{ sd_cross_add(dvb, cs, tp, dv); sd_cross_add(dvb, cs, vp, dth); }}
    }}
    for (i = 0; i < 3; ++i) {{
        s->th[s->k % {width}][i] = dth[i];
        s->dv[s->k % {width}][i] = dv[i];
    }}
    s->k += 1;
    sd_nav_step(s, phi, dvb);
    for (i = 0; i < 3; ++i) {{ pos[i] = s->pos[i]; vel[i] = s->v[i]; }}
    for (i = 0; i < 4; ++i) q[i] = s->q[i];
    return 1;
}}
"""
    steady = sum(1 for c in coning[-1] if c != 0) + 2 * sum(1 for c in scul[-1] if c != 0)
    ops = _sum(_times(_CROSS, steady), _ROTATION_COMP, _STEP, _UPDATE)
    return fields, body, ops


#: Operation counts, from the generated code. A cross product accumulated with a
#: coefficient (9 mul, 6 add); the rotation compensation (15 mul, 12 add, 3 div); the
#: navigation step without its quaternion updates, in the steady state (four-point rules;
#: the start-up's two- and three-point updates and the rates of the initial state cost
#: less): extrapolation of the nine rates (18 mul, 18 add), the predicted ζ by
#: Adams–Moulton (12 mul, 9 add, 3 div), three rotations to n (54 mul, 36 add), seven
#: cross products (42 mul, 21 add), the changes of the body's velocity increment and of
#: ω_in (3 mul, 6 add), velocity (15 mul, 30 add, 12 div), predicted position (12 mul,
#: 12 add, 3 div), the Earth rates at the update's end: radii, gravity, ω_in, Coriolis,
#: position rates (21 mul, 15 add, 10 div, sqrt, sin, cos; the compiler folds the constant
#: sub-expressions), the velocity correction (6 mul, 6 add), position (12 mul, 12 add,
#: 3 div), ζ from the end rates with the frame's coning (15 mul, 12 add, 6 div). The body
#: update on its sin/cos branch (as :mod:`strapdown.codegen.export_c` counts it) and the
#: navigation-frame rotation on its series branch, |ζ|/2 < 1e-2, which it takes for any
#: update period below ~270 s (7 mul, 7 add, 7 div instead of sin, cos and a division).
_CROSS = {"mul": 9, "add": 6}
_ROTATION_COMP = {"mul": 15, "add": 12, "div": 3}
_STEP = {"mul": 210, "add": 177, "div": 37, "sqrt": 1, "sin": 1, "cos": 1}
_UPDATE = {"mul": 31 + 38, "add": 17 + 24, "div": 2 + 8, "sqrt": 2 + 2, "sin": 1, "cos": 1}


def _sum(*parts: dict[str, int]) -> dict[str, int]:
    out = {k: 0 for k in ("mul", "add", "div", "sqrt", "sin", "cos", "tan")}
    for p in parts:
        for k, v in p.items():
            out[k] += v
    return out


def _times(d: dict[str, int], n: int) -> dict[str, int]:
    return {k: v * n for k, v in d.items()}


def _nav_structure(structure: str) -> UpdateStructure:
    """The registered structure, if the velocity algorithms (and so this code) run in it."""
    found = STRUCTURE_REGISTRY.get(structure)
    if found is None or not found.runs_velocity:
        raise ValueError(f"nav supports the structures {', '.join(nav_structures())}, got "
                         f"{structure!r}")
    return found


def nav_ops(structure: str, n: int, velocity_set: VelocitySet = DEFAULT_VELOCITY_SET
            ) -> dict[str, int]:
    """Operations per update of the generated navigation code."""
    return (_conventional(n, velocity_set) if _nav_structure(structure).whole_updates
            else _single_chain(n))[2]


_API = """
/* sizeof(NAME_state), for callers through a foreign-function interface. */
unsigned long NAME_state_size(void);
/* Initialise: sample interval h (s), position pos0 = (latitude, longitude in rad, height in
   m above the ellipsoid), NED velocity v0 (m/s), attitude q0 = q_n_b (unit, scalar first). */
void NAME_init(NAME_state *s, NAME_real h, const NAME_real pos0[3], const NAME_real v0[3],
               const NAME_real q0[4]);
/* Back to the state right after init. */
void NAME_reset(NAME_state *s);
/* Feed one gyro increment (rad) and one accelerometer increment (m/s) over h; returns 1 and
   writes position, NED velocity and q_n_b when an update completes, else 0. */
int NAME_update(NAME_state *s, const NAME_real dth[3], const NAME_real dv[3], NAME_real pos[3],
                NAME_real vel[3], NAME_real q[4]);
"""

_INIT = """
unsigned long NAME_state_size(void) { return (unsigned long)sizeof(NAME_state); }

void NAME_init(NAME_state *s, NAME_real h, const NAME_real pos0[3], const NAME_real v0[3],
               const NAME_real q0[4])
{
    int i;
    s->h = h;
    s->period = PERIOD;
    for (i = 0; i < 3; ++i) { s->pos0[i] = s->pos[i] = pos0[i]; s->v0[i] = s->v[i] = v0[i]; }
    for (i = 0; i < 4; ++i) s->q0[i] = s->q[i] = q0[i];
    for (i = 0; i < 36; ++i) s->hist[i / 12][i % 12] = 0.0;
    s->nh = 0;
    s->COUNTER = 0;
}

void NAME_reset(NAME_state *s)
{
    NAME_real p[3], v[3], q[4];
    int i;
    for (i = 0; i < 3; ++i) { p[i] = s->pos0[i]; v[i] = s->v0[i]; }
    for (i = 0; i < 4; ++i) q[i] = s->q0[i];
    NAME_init(s, s->h, p, v, q);
}
"""


def _velocity_note(n: int, velocity_set: VelocitySet) -> str:
    """The header's line on the sculling coefficients: the classical set's wording wherever
    the set run is the classical one (the single chain, N ≤ 2), so that code is unchanged."""
    if (sculling_matrix(n, exact=True, velocity_set=velocity_set)
            == sculling_matrix(n, exact=True)):
        return ("sculling coefficients from the designer's sculling target (= the coning set, "
                "Ignagni 1998).")
    return (f"sculling coefficients: velocity set {velocity_set}, the designer's coning-force "
            "target on all pairs\n * (classical sculling and a body coning in a constant "
            "specific force, both to order 2N).")


def generate_nav(structure: str, n: int, name: str, update_helpers: str,
                 velocity_set: VelocitySet = DEFAULT_VELOCITY_SET
                 ) -> tuple[str, str, dict[str, int]]:
    """``(header, source, ops)`` of the navigation update (see the module docstring).

    ``update_helpers``: the C of ``sd_update`` and ``sd_cross_add`` (shared with the attitude
    export, :mod:`strapdown.codegen.export_c`). ``velocity_set``: the conventional
    structure's sculling pairs, as :func:`strapdown.navigation.navigate` takes
    them (the library's default; the single chain has one set).
    """
    velocity_set = effective_velocity_set(_nav_structure(structure), velocity_set)
    if _nav_structure(structure).whole_updates:  # conventional: an update every N samples
        fields, body, ops = _conventional(n, velocity_set)
        period, counter = f"{n}.0 * h", "count"
        what = f"an update every N = {n} samples"
    else:
        fields, body, ops = _single_chain(n)
        period, counter = "h", "k"
        what = f"single chain, an update every sample with N = {n} accuracy"
    struct = (f"typedef struct {{\n    NAME_real h, period;\n{fields}\n"
              "    NAME_real pos[3], v[3], q[4], hist[3][12];\n    int nh;\n"
              "    NAME_real pos0[3], v0[3], q0[4];\n} NAME_state;")
    guard = name.upper() + "_H"
    header = f"""/* {name}.h — generated by strapdown export-c. Do not edit.
 * Navigation on the WGS-84 Earth (NED): coning, rotation and sculling compensated body
 * increments ({what}), velocity with Earth rate, transport rate and Somigliana gravity,
 * position by Adams-Moulton quadrature of the Earth rates, attitude q_n_b. Savage (1998b);
 * {_velocity_note(n, velocity_set)}
 * Real type: double. Input: gyro increments (rad), accelerometer increments (m/s).
 * Operations per update: {", ".join(f"{k} {v}" for k, v in ops.items())}.
 */
#ifndef {guard}
#define {guard}

typedef double NAME_real;

{struct}
{_API}
#endif
"""
    init = _INIT.replace("PERIOD", period).replace("COUNTER", counter)
    if "sd_cross_add(" not in body:  # N = 1 conventional: no pair terms
        update_helpers = update_helpers[:update_helpers.index("static void sd_cross_add")]
    source = f"""/* {name}.c — generated by strapdown export-c. Do not edit. See {name}.h. */
#include <math.h>
#include "{name}.h"
{update_helpers}{_helpers()}{_step()}{init}{body}"""
    return fill_names(header, name), fill_names(source, name), ops
