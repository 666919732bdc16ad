"""Count the plant forks outside the plant modules: ``python benchmarks/plant_forks.py [--list] [--root SRC]``.

A plant fork is code that asks *which plant* a vehicle flies rather than asking the plant
(``quadcruise.sim.plants``). Each source line of ``src/quadcruise`` outside ``sim/plants/``,
with its comments and strings left out (:mod:`tokenize`; an f-string is kept whole, its
expressions being code), counts once if it holds any of:

- ``isinstance(..., RotorVehicle)`` or ``isinstance(..., Vehicle)`` (a vehicle class asked; a
  check that takes either, ``isinstance(v, (Vehicle, RotorVehicle))``, asks no plant and is not
  counted);
- a conditional on a plant flag: ``if``/``elif``/``while``/``and``/``or``/``not`` or a
  ternary's ``if`` followed by ``rotor`` or ``x.rotor`` (the name itself, not ``rotors`` or
  ``rotor_loss``; nor ``rotor is None``, a rotor's index), or ``rotor`` followed by
  ``and``/``or``/``else``;
- a plant's array or base as the test: ``rotor_states``/``rotor_base``/``rotor_speeds``/
  ``rotor_batch(...)``/``rotor_names`` then ``is None`` or ``is not None``;
- a plant's name compared: ``plant ==``/``plant !=``, ``== "rotor"``/``== "paper"`` (either
  quote, either operator, either side).

``--list`` prints each line counted; the exit status is 0. The figure is reproducible from a
checkout: ``python benchmarks/plant_forks.py --root <tree>/src``.
"""

from __future__ import annotations

import argparse
import io
import re
import sys
import tokenize
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1] / "src"
PLANT_MODULES = ("quadcruise/sim/plants/",)
FLAG = r"(?:\b\w+\.)?rotor\b(?!\s*[=(\[])(?!\s+is\b)"
PATTERNS = {
    "isinstance": re.compile(r"isinstance\([^,]*,\s*(?:RotorVehicle|Vehicle)\s*\)"),
    "flag": re.compile(
        rf"(?:\b(?:if|elif|while|and|or|not)\s+\(?\s*{FLAG})|(?:\brotor\s+(?:and|or|else)\b)|(?:\bif\s+not\s+{FLAG})"
    ),
    "array": re.compile(
        r"\b(?:rotor_states|rotor_base|rotor_speeds|rotor_names|rotor_batch\([^)]*\))\s+is\s+(?:not\s+)?None"
    ),
    "name": re.compile(r"\bplant\b\s*[!=]=|[!=]=\s*['\"](?:rotor|paper)['\"]|['\"](?:rotor|paper)['\"]\s*[!=]="),
}


def code_lines(text: str) -> dict[int, str]:
    """Each line as written, its comments cut and each string but ``"rotor"``/``"paper"`` as ``''`` (tokenize)."""
    lines = text.splitlines()
    cuts: list[tuple[tuple[int, int], tuple[int, int], str]] = []
    for tok in tokenize.generate_tokens(io.StringIO(text).readline):
        if tok.type == tokenize.COMMENT:
            cuts.append((tok.start, tok.end, ""))
        elif (
            tok.type == tokenize.STRING
            and not re.match(r"[rbRB]*[fF]", tok.string)  # an f-string's expressions are code: kept whole
            and not re.fullmatch(r"[rbuRBU]*(['\"])(?:rotor|paper)\1", tok.string)
        ):
            cuts.append((tok.start, tok.end, "''"))
    for (r0, c0), (r1, c1), put in reversed(cuts):  # from the end, so earlier positions hold
        head, tail = lines[r0 - 1][:c0], lines[r1 - 1][c1:]
        lines[r0 - 1 : r1] = [head + put + tail] + [""] * (r1 - r0)
    return {i + 1: line for i, line in enumerate(lines) if line.strip()}


def forks(root: Path) -> list[tuple[str, int, str, str]]:
    """(file, line, kind, code) of each plant fork under ``root`` outside the plant modules."""
    found = []
    for path in sorted(root.rglob("*.py")):
        rel = path.relative_to(root).as_posix()
        if any(rel.startswith(p) for p in PLANT_MODULES):
            continue
        for number, code in code_lines(path.read_text()).items():
            kinds = [k for k, p in PATTERNS.items() if p.search(code)]
            if kinds:
                found.append((rel, number, kinds[0], code))
    return found


def main(argv: list[str] | None = None) -> int:
    """Print the count (and with ``--list`` each fork)."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--root", type=Path, default=ROOT, help="the src folder (default: this checkout's)")
    parser.add_argument("--list", action="store_true", help="print each fork")
    args = parser.parse_args(argv)
    found = forks(args.root)
    if args.list:
        for rel, number, kind, code in found:
            print(f"{rel}:{number}: [{kind}] {code[:150]}")
    files = len({f[0] for f in found})
    print(f"{len(found)} plant forks in {files} files outside {', '.join(PLANT_MODULES)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
