"""What the fuzz suite runs a file through: every reader of its format (the Python API) and,
through the console entry point, every command that reads such a file.

:data:`API` maps a format to ``(name, call)`` pairs, ``call(path, scratch)`` reading the
file (and, for ``run``, ``ahrs``, ``compare``, writing into ``scratch``); :data:`CLI` maps
a format to the argument lists of ``python -m strapdown.cli`` (``{imu}`` and ``{out}``
filled in). The only acceptable outcomes are success and :class:`strapdown.InputError`.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

__all__ = ["API", "CLI", "api_targets"]


def _imu(kind: str, units: str | None, **kw) -> Callable[[Path, Path], object]:
    def call(path: Path, scratch: Path) -> object:
        from strapdown.io import read_imu

        return read_imu(path, kind=kind, units=units, unit_check="error", **kw)

    return call


def _run(kind: str, units: str | None, out: str = "a.csv", **kw) -> Callable[[Path, Path], object]:
    def call(path: Path, scratch: Path) -> object:
        from strapdown.apps.run import run_log

        return run_log(path, scratch / out, kind=kind, units=units, **kw)

    return call


def _ahrs(path: Path, scratch: Path) -> object:
    from strapdown.apps.ahrs_log import run_ahrs

    return run_ahrs(path, scratch / "ahrs.csv", gyro_units=None if path.suffix == ".mat"
                    else "rad/s", acc_units=None if path.suffix == ".mat" else "m/s2")


def _ahrs_read(path: Path, scratch: Path) -> object:
    from strapdown.apps.ahrs_log import read_ahrs_log

    mat = path.suffix == ".mat"
    return read_ahrs_log(path, gyro_units=None if mat else "rad/s",
                         acc_units=None if mat else "m/s2")


def _truth(path: Path, scratch: Path) -> object:
    from strapdown.apps.compare import _read_truth

    return _read_truth(path)


def _nav(path: Path, scratch: Path) -> object:
    from strapdown.apps.nav import read_nav_log

    return read_nav_log(path, kind="rate", units=None if path.suffix == ".mat" else "rad/s",
                        acc_units=None if path.suffix == ".mat" else "m/s2")


def _broad(path: Path, scratch: Path) -> object:
    from strapdown.io.broad import read_broad

    return read_broad(path)


def _scenario(path: Path, scratch: Path) -> object:
    from strapdown.apps.sweep import cases, load_scenario

    return cases(load_scenario(path))


def _sweep(path: Path, scratch: Path) -> object:
    from strapdown.apps.sweep import sweep

    return sweep(path, scratch / "sweep", workers=1, formats=["csv"], max_cases=2)


API: dict[str, list[tuple[str, Callable[[Path, Path], object]]]] = {
    "csv": [("read_imu rate", _imu("rate", "rad/s")),
            ("read_imu increment", _imu("increment", "rad")),
            ("read_ahrs_log", _ahrs_read), ("truth", _truth), ("nav", _nav),
            ("run rate", _run("rate", "rad/s", angles="none")),
            ("ahrs", _ahrs)],
    "npy": [("read_imu rate", _imu("rate", "rad/s")),
            ("read_imu increment", _imu("increment", "rad")),
            ("truth", _truth),
            ("run increment (streamed)", _run("increment", "rad", out="a.npz")),
            ("run rate", _run("rate", "rad/s", angles="none"))],
    "npz": [("read_imu rate", _imu("rate", "rad/s")),
            ("read_imu increment", _imu("increment", "rad")),
            ("truth", _truth), ("nav", _nav),
            ("run increment", _run("increment", "rad"))],
    "mat": [("read_imu rate", _imu("rate", None)),
            ("read_imu increment", _imu("increment", "rad")),
            ("read_broad", _broad), ("read_ahrs_log", _ahrs_read), ("nav", _nav),
            ("run rate", _run("rate", None, angles="none"))],
    "h5": [("read_imu rate", _imu("rate", "rad/s")),
           ("read_imu increment", _imu("increment", "rad")), ("nav", _nav)],
    "toml": [("load_scenario", _scenario), ("sweep", _sweep)],
}


def api_targets(fmt: str) -> list[tuple[str, Callable[[Path, Path], object]]]:
    """The API calls a file of format ``fmt`` goes through."""
    return API[fmt]


#: Command lines per format (``{imu}``: the file, ``{out}``: a scratch directory).
CLI: dict[str, list[list[str]]] = {
    "csv": [["run", "--imu", "{imu}", "--rates", "--units", "rad/s", "--out", "{out}/a.csv"],
            ["ahrs", "--imu", "{imu}", "--gyro-units", "rad/s", "--acc-units", "m/s2",
             "--out", "{out}/a.csv"],
            ["compare", "--imu", "{imu}", "--rates", "--units", "rad/s", "--algorithms",
             "rk4", "rate-three", "--out", "{out}/cmp"]],
    "npy": [["run", "--imu", "{imu}", "--increments", "--units", "rad", "--out",
             "{out}/a.npz"],
            ["compare", "--imu", "{imu}", "--increments", "--units", "rad", "--algorithms",
             "rotvec:N=2", "--out", "{out}/cmp"]],
    "npz": [["run", "--imu", "{imu}", "--rates", "--units", "rad/s", "--out", "{out}/a.csv"],
            ["nav", "--imu", "{imu}", "--units", "rad/s", "--acc-units", "m/s2",
             "--init-lat", "45", "--init-lon", "7", "--init-height", "0", "--out",
             "{out}/n.csv"]],
    "mat": [["run", "--imu", "{imu}", "--rates", "--out", "{out}/a.csv"],
            ["ahrs", "--imu", "{imu}", "--out", "{out}/a.csv"]],
    "h5": [["run", "--imu", "{imu}", "--rates", "--units", "rad/s", "--out", "{out}/a.csv"]],
    "toml": [["sweep", "{imu}", "--out", "{out}/sw", "--workers", "1", "--format", "csv",
              "--max-cases", "2"]],
}
