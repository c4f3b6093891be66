"""Benchmark: PROV → RDF quads, the RDF texts, and SHACL validation.

* ``to_quads`` on the large scenario of ``bench/compile.py`` (100 robots,
  2,000 poses, 500 tasks), target ≥ 200,000 quads/s, split into its two steps
  (the PROV-O mapping to N-Quads lines; Oxigraph's parser making the quads)
  and set against the other way of making quads: calling ``Quad(...)`` from
  Python for each one (timed from ready-made terms, so a lower bound);
* each RDF format written from the same document;
* SHACL (``check_scenario_shapes``) on scenario_c: the first call, which
  imports pyshacl and reads the shapes, and warm calls; target well under a
  second; and ``exscec check`` on scenario_c end to end.

    python bench/rdf.py [--repeat 5]
"""

from __future__ import annotations

import argparse
import gc
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path

from pyoxigraph import Quad, RdfFormat, parse

from exsce_dsl.lang import load_spec
from exsce_dsl.prov import compile_scenario
from exsce_dsl.rdf import check_scenario_shapes, serialize, to_quads
from exsce_dsl.rdf.prov_o import nquad_lines, quads_of_lines

sys.path.insert(0, str(Path(__file__).parent))
from compile import write_spec  # noqa: E402  (the sibling benchmark's scenario)

EXAMPLE = Path(__file__).resolve().parents[1] / "examples" / "brsu_building_c" / "scenario_c.exsce"


def best(func: Callable[[], object], repeat: int) -> float:
    times = []
    for _ in range(repeat):
        gc.collect()
        start = time.perf_counter()
        func()
        times.append(time.perf_counter() - start)
    return min(times)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--repeat", type=int, default=5)
    repeat = parser.parse_args().repeat

    with tempfile.TemporaryDirectory() as tmp:
        document = compile_scenario(load_spec(write_spec(Path(tmp))).scenario())
    quads = to_quads(document)
    n = len(quads)
    print(f"large scenario: {n:,} quads in {len(document.bundles)} named graphs")

    total = best(lambda: to_quads(document), repeat)
    lines = nquad_lines(document)
    mapping = best(lambda: nquad_lines(document), repeat)
    parsing = best(lambda: quads_of_lines(lines), repeat)
    text = "".join(lines)
    strict = best(lambda: list(parse(text, format=RdfFormat.N_QUADS)), repeat)
    terms = [(q.subject, q.predicate, q.object, q.graph_name) for q in quads]
    direct = best(lambda: [Quad(s, p, o, g) for s, p, o, g in terms], repeat)
    verdict = "meets" if n / total >= 200_000 else "MISSES"
    print(f"to_quads: {total:.3f} s, {n / total:,.0f} quads/s ({verdict} the 200,000 quads/s target)")
    print(f"  PROV-O mapping to N-Quads lines: {mapping:.3f} s ({n / mapping:,.0f} quads/s)")
    print(f"  Oxigraph parsing them (lenient): {parsing:.3f} s ({n / parsing:,.0f} quads/s)")
    print(f"  (strict parsing, checking every IRI again: {strict:.3f} s)")
    print(
        f"  the other way, Quad(s, p, o, g) from Python for each quad: {direct:.3f} s for the "
        f"constructor calls alone, {direct / parsing:.1f}× the parser's time for the same quads"
    )
    for fmt in ("nq", "trig", "ttl", "jsonld"):
        seconds = best(lambda fmt=fmt: serialize(document, fmt), max(1, repeat // 2))  # type: ignore[misc]
        print(f"  serialize {fmt:>6}: {seconds:.3f} s")

    scenario = load_spec(EXAMPLE).scenario()
    start = time.perf_counter()
    assert check_scenario_shapes(scenario) == []
    first = time.perf_counter() - start
    warm = best(lambda: check_scenario_shapes(scenario), repeat)
    print(f"SHACL on scenario_c: first call {first:.3f} s (imports pyshacl, reads the shapes)")
    print(f"  then {warm:.3f} s a call ({'well under' if warm < 0.5 else 'NOT well under'} a second)")
    exscec = Path(sys.executable).with_name("exscec")
    start = time.perf_counter()
    subprocess.run([str(exscec), "check", str(EXAMPLE)], check=True, capture_output=True)
    print(f"exscec check scenario_c.exsce, end to end: {time.perf_counter() - start:.2f} s")


if __name__ == "__main__":
    main()
