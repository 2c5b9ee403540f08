"""``strapdown coefficients``: a structure's coning coefficients derived exactly."""

from __future__ import annotations

import argparse

from strapdown.cli._common import json_arg, print_json

__all__ = ["add_parser", "run"]


def add_parser(subparsers) -> argparse.ArgumentParser:
    """Register ``coefficients`` (its options are added when it is used)."""
    p = subparsers.add_parser(
        "coefficients", arguments=_arguments,
        help="derive coning coefficients exactly for an algorithm structure",
        description="Derive a structure's coefficients in exact rational arithmetic and print "
        "them with the classical-coning drift law they achieve: drift about the cone axis = "
        "−drift_constant · a²Ω(Ωh)^order.")
    p.set_defaults(handler=run)
    return p


def _arguments(p: argparse.ArgumentParser) -> None:
    from strapdown.design import FORMS, RULES, TARGETS

    p.add_argument("--form", choices=FORMS, required=True, help="algorithm structure")
    p.add_argument("--subsamples", type=int, required=True,
                   help="N, increments (or rate samples) per update")
    p.add_argument("--target", choices=TARGETS, default="coning",
                   help="design target: coning (the highest order of classical-coning drift), "
                   "polynomial (polynomial-rate conditions, lowest degrees first) or sculling "
                   "(the highest order of classical-sculling velocity error; increment input)")
    p.add_argument("--rule", choices=RULES, default="polynomial",
                   help="how to settle coefficients the target leaves free")
    p.add_argument("--previous", type=int, default=None,
                   help="uncompressed form: increments from earlier intervals (default: N)")
    p.add_argument("--ignore-quadrature", action="store_true",
                   help="rate input: fit β only, ignoring the α quadrature error (shows what "
                   "such a derivation claims; the true drift is printed beside it)")
    json_arg(p)


def run(args: argparse.Namespace) -> int:
    """Derive the coefficients and print them with their drift law (text or ``--json``)."""
    from strapdown.design import classical_coning_drift, derive, structure_by_name

    st = structure_by_name(args.form, args.subsamples, previous=args.previous)
    d = derive(st, target=args.target, rule=args.rule, quadrature=not args.ignore_quadrature)
    rec = d.to_dict()
    true_drift = None
    if args.ignore_quadrature and st.input == "rate":
        true_drift = classical_coning_drift(st, d.coefficients)
        order, const = true_drift
        rec["true_order"] = order
        rec["true_drift_constant"] = None if const is None else _fraction(const)
    if args.json:
        print_json(rec)
        return 0
    width = max((len(t) for t in rec["terms"]), default=4)
    lines = [f"form          {rec['form']} ({rec['input']} input)",
             f"target        {rec['target']} (free coefficients settled by {rec['rule']})"]
    for term, frac, dec in zip(rec["terms"], rec["coefficients"], rec["decimals"], strict=True):
        lines.append(f"  {term:{width}s}  {frac:>14s}  {dec: .17g}")
    if not rec["terms"]:
        lines.append("  (no cross-product terms)")
    if args.target == "sculling":
        lines.append(f"velocity      {_law(d.drift_constant, d.order, 'θ0 A cos ψ')} rectified "
                     "velocity error rate, normal to both vibrations")
    else:
        lines.append(f"drift         {_law(d.drift_constant, d.order)} about the cone axis")
    if true_drift is not None:
        order, const = true_drift
        lines.append(f"true drift    {_law(const, order)} (with the quadrature error)")
    print("\n".join(lines))
    return 0


def _fraction(f) -> str:
    return f"{f.numerator}/{f.denominator}"


def _law(const, order, amplitude: str = "a²Ω") -> str:
    """``drift = −c · a²Ω(Ωh)^order`` written with its sign resolved."""
    if order is None:
        return "none up to the series length examined"
    sign = "−" if const > 0 else "+"
    return f"{sign}{_fraction(abs(const))} · {amplitude}(Ωh)^{order}"
