"""Paper reproductions: each writes tables (CSV + Markdown), figures (PNG) and ``report.md``.

Printed numbers are kept beside ours with a status column; where a paper
does not reproduce we say why and give the number we measured.

:data:`REPRODUCTIONS` names every reproduction (the names ``strapdown reproduce``
accepts) with its module and what it reproduces; :func:`reproduction` imports one
module on demand (they import numpy, matplotlib and the algorithms).
"""

from __future__ import annotations

import importlib
from dataclasses import dataclass
from types import ModuleType
from typing import Literal, get_args

__all__ = ["REPRODUCTIONS", "Reproduction", "ReproductionName", "reproduction"]

#: The reproductions' command-line names, in the order the command line lists them.
ReproductionName = Literal["li2017", "wang-rate", "wang-sliding", "plaksiy2024", "zhang2021",
                           "sculling", "high-order"]


@dataclass(frozen=True)
class Reproduction:
    """One paper reproduction: its module (with ``reproduce(out, *, progress)``) and subject."""

    module: str
    subject: str


#: Every reproduction by its command-line name, in the order the command line lists them.
REPRODUCTIONS: dict[ReproductionName, Reproduction] = {
    "li2017": Reproduction("strapdown.reproduce.li2017",
                           "Li & Zhang (2017): coning coefficients and update structures"),
    "wang-rate": Reproduction("strapdown.reproduce.wang_rate",
                              "the rate-input algorithms of Wang, Wang & Wang"),
    "wang-sliding": Reproduction("strapdown.reproduce.wang_sliding",
                                 "their three-filter EKF comparison on the loiter flight"),
    "plaksiy2024": Reproduction("strapdown.reproduce.plaksiy2024",
                                "Plaksiy's Krylov-model study of algorithms A1-A3"),
    "zhang2021": Reproduction("strapdown.reproduce.zhang2021", "Zhang & Yu's cone angles"),
    "sculling": Reproduction("strapdown.reproduce.sculling",
                             "sculling law and duality (Savage, Ignagni), WGS-84 navigation, "
                             "smsfusion"),
    "high-order": Reproduction("strapdown.reproduce.high_order",
                               "finite-amplitude coning sets (triple cross products), spin plus "
                               "coning, and advise on a vibration log"),
}


if tuple(REPRODUCTIONS) != get_args(ReproductionName):  # one list of names: the Literal
    raise RuntimeError(f"REPRODUCTIONS {tuple(REPRODUCTIONS)} and ReproductionName "
                       f"{get_args(ReproductionName)} disagree")


def reproduction(name: ReproductionName) -> ModuleType:
    """The module of reproduction ``name`` (imported now); an unknown name lists the known."""
    try:
        entry = REPRODUCTIONS[name]
    except (KeyError, TypeError):
        raise ValueError(f"unknown reproduction {name!r}; choose one of "
                         f"{', '.join(REPRODUCTIONS)}") from None
    return importlib.import_module(entry.module)
