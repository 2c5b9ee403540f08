"""Generate allocation-free C99 for the AHRS filter (``strapdown export-c --algorithm ahrs``).

The C (``templates/ahrs.c.in``, ``templates/ahrs.h.in``) mirrors
:func:`strapdown.ahrs._kernel.ekf_kernel` function by function — each static function
names the kernel function it repeats; the covariance updates use P's symmetry and zero
blocks, so the arithmetic differs at round-off (see the template's head) — and runs the
causal filter of :func:`strapdown.ahrs.ekf` one sample at a time: the initial window
(``init_window_s``; when neither it nor its first ``init_still_min_s`` is still, a start
in motion's ``moving_start_window_s``) is buffered, its (still part's) means give the
initial attitude, the reference field and gravity as the library computes them, then
the buffered samples and every later one go through the same epochs. In double precision
it equals the library to round-off (the test suite holds it to 1e-8 rad at every sample on
BROAD recordings).

What the template does not take from the kernel it takes from here, computed by the
library's own functions so the values cannot drift: the tuning is the kernel's
:class:`~strapdown.ahrs._kernel.Params` record for an :class:`~strapdown.ahrs.AhrsConfig`
(``filter._params``: the same low-pass coefficients, averaging counts, delays in
samples), the propagation algorithm's window (``filter._algorithm``), and ``P0``
(``filter._initial_covariance``). Only what the record learns from data (the reference
field, gravity as measured, whether there is a magnetometer) is in the state.
"""

from __future__ import annotations

import math
import re
import typing
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from strapdown.ahrs import AhrsConfig
from strapdown.ahrs import _kernel as K
from strapdown.ahrs import filter as F
from strapdown.ahrs.flags import MeasurementFlag
from strapdown.ahrs.saturation import DECLIP_ACROSS

__all__ = ["LEARNED", "AhrsExport", "export_ahrs", "generate_ahrs", "propagation_supported"]

_TEMPLATES = Path(__file__).parent / "templates"
#: Params fields the filter learns from the record (state, not constants); the low-pass
#: coefficients (arrays LP, MC); the delay ring's size (a macro); the offline switch.
LEARNED = ("ref_norm", "ref_dip", "ref_heading", "use_magnetometer", "gravity_measured",
           "gravity_known", "gravity_learned", "mag_provisional_s", "lp_settle")
_NOT_IN_PRM = (*LEARNED, "store_covariance", "mag_delay_max", "rest_tau",
               *(f"{p}_{c}" for p in ("lp", "mc") for c in ("b0", "b1", "b2", "a1", "a2")))
_MATH = ("sqrt", "sin", "cos", "atan", "atan2", "asin", "exp", "pow", "fabs")
_FLOAT_LITERAL = re.compile(r"(?<![\w.])(\d+\.\d*(?:[eE][-+]?\d+)?|\d+[eE][-+]?\d+)(?![\w.])")


@dataclass(frozen=True)
class AhrsExport:
    """Generated AHRS source (``name.h``, ``name.c``) and what it was made from."""

    name: str
    header: str
    source: str
    real: str
    h: float
    mag: bool
    algorithm: str
    config: AhrsConfig
    init_samples: int
    moving_samples: int  #: a start in motion's window, samples (moving_start_window_s)


def _lit(x: float, real: str) -> str:
    """A C literal of ``real``'s type (``(NAME_real)INFINITY`` for +inf)."""
    if math.isinf(x):
        return "(NAME_real)INFINITY"
    s = repr(float(x))
    if "e" not in s and "." not in s:
        s += ".0"
    return s + ("f" if real == "float" else "")


def propagation_supported(algorithm: str) -> dict:
    """The propagation record of ``algorithm`` (``filter._algorithm``) if the C template
    runs it: the windowed rate algorithms in the conventional structure and RK4.

    Raises
    ------
    ValueError
        For the sliding structure and the increment (rotvec) algorithms, naming them.
    """
    a = F._algorithm(algorithm)
    if not a["is_rate"] or a["lag"] != 1:
        raise ValueError(f"export-c --algorithm ahrs runs the rate algorithms in the "
                         f"conventional structure (rate-single, rate-two, rate-three) and rk4; "
                         f"{algorithm!r} is {'sliding' if a['lag'] != 1 else 'on increments'}")
    return a


def _params(cfg: AhrsConfig, mag: bool, h: float, stride: int) -> K.Params:
    """The kernel's parameter record for this configuration (learned fields neutral)."""
    return F._params(cfg, (1.0, 0.0, 0.0), mag, h, stride * h,
                     F._Start(True, cfg.gravity, True, cfg.attitude_sigma0))


def _prm_struct(params: K.Params, rk4: bool, real: str) -> str:
    """``NAME_params`` (the kernel's Params fields that are constants) and ``PRM``."""
    types = typing.get_type_hints(K.Params)
    ctype = {float: "NAME_real", int: "long", bool: "int"}
    fields = [(f, types[f], getattr(params, f)) for f in K.Params._fields
              if f not in _NOT_IN_PRM]
    fields.append(("rk4", bool, rk4))
    decl = "\n".join(f"    {ctype[t]} {f};" for f, t, _ in fields)
    init = ",\n".join(f"    .{f} = " + (_lit(v, real) if t is float else str(int(v)))
                      for f, t, v in fields)
    return (f"/* the kernel's Params record (strapdown.ahrs._kernel.Params), constants */\n"
            f"typedef struct {{\n{decl}\n}} NAME_params;\n\n"
            f"static const NAME_params PRM = {{\n{init}\n}};")


def _table(name: str, ctype: str, values, fmt) -> str:
    vals = list(values) or [0]
    return f"static const {ctype} {name}[{len(vals)}] = {{{', '.join(fmt(v) for v in vals)}}};"


def _sizes(cfg: AhrsConfig, params: K.Params, prop: dict, mag: bool, n_init: int,
           n_min: int, n_move: int) -> dict:
    """The header's size macros (without the prefix)."""
    stride = int(prop["stride"])
    n_win = max(n_init, n_move)
    dmax = (params.mag_delay_max if params.estimate_mag_delay else params.mag_delay) if mag else 0
    max_off = int(np.max(prop["offsets"])) if len(prop["offsets"]) else 2
    return {"NX": 6 + 3 * (cfg.acc_model == "raw") + 3 * cfg.estimate_acc_bias,
            "INIT_SAMPLES": n_init, "STILL_MIN_SAMPLES": n_min, "MOVING_SAMPLES": n_move,
            "WIN_SAMPLES": n_win,
            "MAG_WINDOW": n_win if mag else 1,
            # the gyro history: a power of two, so that k % XH is a mask
            "XH": 1 << (max(max_off + 1, dmax + 2, 3) - 1).bit_length(), "DMAX": dmax,
            "ND": (dmax + stride // 2) // stride + 1 if mag else 1}


def _epoch_constants(cfg: AhrsConfig, params: K.Params, prop: dict, h: float,
                     real: str) -> dict[str, str]:
    """Macros the C would otherwise compute per update from constants: 1/T and the Singer
    process's exponentials over the epoch's (constant) T (``_process_noise``), and the
    sample counts from which ``max(alpha, 1/n)`` is ``alpha`` (the rest detector's and
    the delay estimator's averaging gains: 1/n < alpha/2 there, whatever the rounding)."""
    T = 2.0 * h if prop["rk4"] else int(prop["stride"]) * h  # _rk4_step, _window_step
    rest_alpha = h / cfg.rest_tau
    return {"INV_T": _lit(1.0 / T, real), "EXPT": _lit(math.exp(-T / params.singer_tau), real),
            "EXP2T": _lit(math.exp(-2.0 * T / params.singer_tau), real),
            "REST_N": f"{math.ceil(2.0 / rest_alpha) + 1}L",
            "DELAY_N": f"{math.ceil(2.0 / params.mag_delay_alpha) + 1}L"}


def _constants(cfg: AhrsConfig, params: K.Params, prop: dict, h: float, mag: bool,
               real: str, n_init: int, n_min: int) -> str:
    """The .c file's constants: macros, the Params struct, tables, flags."""
    d = math.radians(cfg.declination_deg)
    lead = cfg.latency_s + (0.5 * h if cfg.gyro_sample == "interval" else 0.0)
    macros = {"TD": _lit(h, real), "STRIDE": str(int(prop["stride"])),
              "END_OFF": str(int(prop["end_off"])), "NODES": str(len(prop["offsets"])),
              "PAIRS": str(len(prop["pi"])), "MAG": str(int(mag)),
              "REST_ALPHA": _lit(h / cfg.rest_tau, real), "LEAD": _lit(lead, real),
              "CLIP_NEAR": _lit(K.CLIP_NEAR, real),
              # saturation.declip's threshold; 0: gyro_declip off
              "DECLIP_ACROSS": _lit(DECLIP_ACROSS if cfg.gyro_declip else 0.0, real),
              "PI": _lit(math.pi, real), "TINY": _lit(1e-300 if real == "double" else 1e-30,
                                                       real),
              "COS_DECL": _lit(math.cos(d), real), "SIN_DECL": _lit(math.sin(d), real),
              "NAN": "((NAME_real)NAN)",
              # a start in motion (filter._initial_covariance, filter._derived)
              "MOVING_SIGMA0_SQ": _lit(cfg.moving_start_sigma0 ** 2, real),
              # a still start's gyro bias, measured over the window (filter._window_bias)
              "WINDOW_BIAS_SIGMA0_SQ": _lit(F.window_bias_sigma(cfg, n_init, h) ** 2, real),
              "WINDOW_MIN_BIAS_SIGMA0_SQ": _lit(F.window_bias_sigma(cfg, n_min, h) ** 2, real),
              "MOVING_MAG_S": _lit(cfg.moving_start_mag_s, real),
              "SETTLE_ALWAYS": str(int(cfg.acc_lowpass_settle)),
              # a start in motion's learning of gravity's norm (_kernel._learn_gravity)
              "LEARN_MAX_TURN": _lit(K.LEARN_MAX_TURN, real),
              "LEARN_MIN_SPIN": _lit(K.LEARN_MIN_SPIN, real),
              **_epoch_constants(cfg, params, prop, h, real)}
    lines = [f"#define PREFIX_{k} {v}" for k, v in macros.items()]
    lit = lambda v: _lit(v, real)  # noqa: E731
    lines += ["", "/* the propagation algorithm's window (filter._algorithm): node offsets, "
              "weights, cross-product pairs */",
              _table("OFFSETS", "long", prop["offsets"], lambda v: str(int(v))),
              _table("WEIGHTS", "NAME_real", prop["weights"], lit),
              _table("PI", "int", prop["pi"], lambda v: str(int(v))),
              _table("PJ", "int", prop["pj"], lambda v: str(int(v))),
              _table("PC", "NAME_real", prop["pc"], lit),
              "/* low-passes of the specific force and of the field's norm and dip (b0, b1, "
              "b2, a1, a2) */",
              *(_table(p.upper(), "NAME_wide", [getattr(params, f"{p}_{c}") for c in
                                                ("b0", "b1", "b2", "a1", "a2")],
                       lambda v: _lit(v, "double")) for p in ("lp", "mc")),
              "/* P0 (filter._initial_covariance), diagonal, of a still start */",
              _table("P0_DIAG", "NAME_real", np.diag(F._initial_covariance(cfg)), lit), "",
              _prm_struct(params, bool(prop["rk4"]), real), "",
              "/* strapdown.ahrs.flags.MeasurementFlag */",
              "enum { " + ", ".join(f"F_{f.name} = {int(f.value)}u" for f in MeasurementFlag)
              + " };"]
    return "\n".join(lines)


def _to_float(text: str) -> str:
    """The template in float: literals get ``f``, libm calls their float forms."""
    text = _FLOAT_LITERAL.sub(lambda m: m.group(1) + "f", text)
    return re.sub(rf"\b({'|'.join(_MATH)})\(", r"\1f(", text)


def _fill(text: str, name: str) -> str:
    return re.sub(r"\bPREFIX_", name.upper() + "_", text).replace("NAME", name)


def _info(cfg: AhrsConfig, algorithm: str, h: float, mag: bool, real: str) -> str:
    changed = {f: v for f, v in cfg.__dict__.items() if v != getattr(AhrsConfig(), f)}
    return (f"   Filter: strapdown.ahrs.ekf, algorithm {algorithm}, sample period {h!r} s "
            f"({1.0 / h:g} Hz), {real}, {'with' if mag else 'without'} magnetometer;\n"
            f"   AhrsConfig defaults{' except ' + repr(changed) if changed else ''}.")


def generate_ahrs(sample_rate_hz: float | None = None, *, h: float | None = None,
                  real: str = "double", mag: bool = True, algorithm: str = "rate-single",
                  config: AhrsConfig | None = None, name: str | None = None) -> AhrsExport:
    """The generated AHRS module (``name.h``, ``name.c``): see the module docstring.

    Parameters
    ----------
    sample_rate_hz, h : float
        The IMU's sample rate (Hz) or period (s), one of them, baked into the code.
    real : {"double", "float"}
    mag : bool
        False: no magnetometer code (``--no-mag``).
    algorithm : str
        The attitude propagation, as for ``strapdown ahrs`` (:func:`propagation_supported`).
    config : AhrsConfig, optional
        The filter's options (default :class:`~strapdown.ahrs.AhrsConfig`).
    name : str, optional
        The C prefix (default ``sd_ahrs``).
    """
    cfg = config or AhrsConfig()
    if (sample_rate_hz is None) == (h is None):
        raise ValueError("give the sample rate (sample_rate_hz) or the period (h), one of them")
    h = 1.0 / float(sample_rate_hz) if sample_rate_hz is not None else float(h)  # type: ignore[arg-type]
    if not (math.isfinite(h) and h > 0):
        raise ValueError(f"the sample period must be positive and finite, got {h!r} s")
    if real not in ("double", "float"):
        raise ValueError(f"real must be 'double' or 'float', got {real!r}")
    name = name or "sd_ahrs"
    if not re.fullmatch(r"[A-Za-z_]\w*", name):
        raise ValueError(f"name must be a C identifier, got {name!r}")
    mag = bool(mag and cfg.use_magnetometer)
    prop = propagation_supported(algorithm)
    params = _params(cfg, mag, h, int(prop["stride"]))
    n_init = F._window_samples(cfg.init_window_s, h)
    # a still start shorter than the window (filter._still_min_window)
    n_min = min(n_init, F._window_samples(cfg.init_still_min_s, h))
    n_move = F._window_samples(cfg.moving_start_window_s, h)  # filter._moving_window
    sizes = "\n".join(f"#define PREFIX_{k} {v}" for k, v in
                      _sizes(cfg, params, prop, mag, n_init, n_min, n_move).items())
    header = (_TEMPLATES / "ahrs.h.in").read_text().replace("@SIZES@", sizes).replace(
        "@INFO@", _info(cfg, algorithm, h, mag, real)).replace("typedef REAL", f"typedef {real}")
    header = header.replace("GUARD", name.upper() + "_H_INCLUDED")
    body = (_TEMPLATES / "ahrs.c.in").read_text()
    if real == "float":
        body = _to_float(body)
    source = body.replace("@CONSTANTS@", _constants(cfg, params, prop, h, mag, real, n_init,
                                                    n_min))
    return AhrsExport(name, _fill(header, name), _fill(source, name), real, h, mag,
                      algorithm, cfg, n_init, n_move)


def export_ahrs(out: str | Path, **kwargs) -> AhrsExport:
    """Generate (:func:`generate_ahrs`) and write ``<name>.h`` and ``<name>.c`` into ``out``
    (each atomically)."""
    from strapdown.io.files import write_text

    exp = generate_ahrs(**kwargs)
    out = Path(out)
    if out.exists() and not out.is_dir():
        raise ValueError(f"--out {out} exists and is not a directory")
    write_text(out / f"{exp.name}.h", exp.header)
    write_text(out / f"{exp.name}.c", exp.source)
    return exp
