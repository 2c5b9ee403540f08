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
                   "polynomial (polynomial-rate conditions, lowest degrees first), sculling "
                   "(the highest order of classical-sculling velocity error; increment input) "
                   "or coning-force (sculling and coning in a constant specific force, order by "
                   "order; increment input)")
    p.add_argument("--rule", choices=RULES, default="polynomial",
                   help="how to settle coefficients the target leaves free")
    p.add_argument("--previous", type=int, default=None,
                   help="uncompressed form: increments from earlier intervals (default: N)")
    p.add_argument("--ignore-quadrature", action="store_true",
                   help="rate input: fit β only, ignoring the α quadrature error (shows what "
                   "such a derivation claims; the true drift is printed beside it)")
    p.add_argument("--triple", action="store_true",
                   help="add the triple cross products θ_N×(θ_(N−m)×θ_N) (single chain: "
                   "θ_k×(θ_(k−m)×θ_k)) and cancel the a⁴ drift too, order by order in Ωh "
                   "(the finite-amplitude sets; increment forms cross-with-last, lag, all-pairs "
                   "and single-chain, target coning)")
    json_arg(p)


def run(args: argparse.Namespace) -> int:
    """Derive the coefficients and print them with their drift law (text or ``--json``)."""
    from strapdown.design import classical_coning_drift, derive, structure_by_name

    st = structure_by_name(args.form, args.subsamples, previous=args.previous)
    if args.triple:
        return _run_triple(args, st)
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
    if args.target == "sculling":  # lint-model: a designer's target, not the motion
        lines.append(f"velocity      {_law(d.drift_constant, d.order, 'θ0 A cos ψ')} rectified "
                     "velocity error rate, normal to both vibrations")
    elif rec["drift_law"].startswith("rectified velocity error rate along the cone axis"):
        lines.append(f"velocity      {_law(d.drift_constant, d.order, 'a² f')} rectified "
                     "velocity error rate along the cone axis, coning in a constant force f "
                     "(the sculling law of the same set: strapdown.design.velocity_error_laws)")
    else:
        lines.append(f"drift         {_law(d.drift_constant, d.order)} about the cone axis")
    if true_drift is not None:
        order, const = true_drift
        lines.append(f"true drift    {_law(const, order)} (with the quadrature error)")
    print("\n".join(lines))
    return 0


_TRIPLE_FORMS = ("cross-with-last", "lag", "all-pairs", "single-chain")


def _run_triple(args: argparse.Namespace, st) -> int:
    """``--triple``: the finite-amplitude design (pairs for a², triple terms for a⁴)."""
    from strapdown.design.finite_amplitude import derive_triple, with_last_triples

    if args.form not in _TRIPLE_FORMS:
        raise ValueError(f"--triple applies to the forms {', '.join(_TRIPLE_FORMS)}, "
                         f"not {args.form!r}")
    classical = args.target == "coning"  # lint-model: a designer's target, not the motion
    if not classical or args.ignore_quadrature or args.subsamples < 2:
        raise ValueError("--triple designs for classical coning (--target coning) with N ≥ 2")
    d = derive_triple(with_last_triples(st))
    rec = d.to_dict()
    if args.json:
        print_json(rec)
        return 0
    names = rec["terms"] + rec["triple_terms"]
    width = max(len(t) for t in names)
    lines = [f"form          {rec['form']} ({rec['input']} input)",
             f"target        coning in a² and a⁴ (free coefficients settled by {rec['rule']}, "
             "triple terms by min-norm)"]
    for term, frac, dec in zip(names, rec["coefficients"] + rec["triple_coefficients"],
                               rec["decimals"] + rec["triple_decimals"], strict=True):
        lines.append(f"  {term:{width}s}  {frac:>14s}  {dec: .17g}")
    laws = [_law(c, q, f"a{'²⁴⁶'[p // 2 - 1]}Ω") for p, q, c in d.amplitude_law]
    lines.append(f"drift         {'  '.join(laws)} about the cone axis (leading term of each "
                 "power of a)")
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
