"""``./run.sh bench mesh``: which Zenoh peers on loopback see each other, and how soon.

Two peer processes A and B (each holding a liveliness token and a queryable, like two
cells claiming one id) and a third peer (the planner) in four topologies:

- ``star``: the planner listens, A and B connect to it and listen nowhere (how cells
  were started before duplicate ids were refused);
- ``star+listen``: the same, A and B also listening on a loopback port the system picks
  (how cells start now: Zenoh's gossip connects them to each other);
- ``together``: as ``star+listen`` with A and B started at the same moment;
- ``apart``: A and B listen on ports of their own and connect nowhere; the planner
  connects to both, after they are up (cells started by hand, then ``session --cells 0
  --connect``).

For each, over ``--repeat`` runs: in how many runs B's liveliness subscriber saw A's
token, in how many B's query reached A's queryable, and how long after the last node
opened its session (B, or the planner for ``apart``) B saw A's token [ms]. Run as a
module (``python -m asp.bench.mesh LISTEN CONNECT NAME``), this file is one such peer.
"""

from __future__ import annotations

import json
import statistics
import subprocess
import sys
import time
from importlib.metadata import version

import zenoh

from bridge.cli_types import ArgumentParser, int_in
from bridge.session import LOOPBACK_ANY_PORT, bound_endpoints, open_session

TOPOLOGIES = ("star", "star+listen", "together", "apart")
WATCH_S = 3.0
"""How long the peers look for each other after the last node opened [s]."""


def peer(listen: list[str], connect: list[str], name: str) -> None:
    """One peer: token ``bench/alive/NAME`` and queryable ``bench/claim/NAME``; prints
    ``ready`` and the endpoints it listens on (their ports as bound), then on a line on
    stdin one JSON line: when it saw each token (Unix time [s]) and which peers answered
    ``bench/claim/*``; exits when stdin closes."""
    seen: dict[str, float] = {}
    with open_session(listen, connect) as session:
        _held = (session.liveliness().declare_subscriber(
                     "bench/alive/*", lambda s: seen.setdefault(str(s.key_expr).rsplit("/", 1)[1], time.time()),
                     history=True),
                 session.declare_queryable(f"bench/claim/{name}", lambda q: q.reply(q.key_expr, name.encode())),
                 session.liveliness().declare_token(f"bench/alive/{name}"))
        print("ready", *bound_endpoints(session, listen), flush=True)
        sys.stdin.readline()
        answered = sorted(r.ok.payload.to_bytes().decode() for r in session.get(
            "bench/claim/*", timeout=2.0, consolidation=zenoh.ConsolidationMode.NONE) if r.ok is not None)
        print(json.dumps({"seen": seen, "answered": answered}), flush=True)
        sys.stdin.read()  # stay up while the other peer queries


def _start(listen: list[str], connect: list[str], name: str) -> subprocess.Popen[str]:
    return subprocess.Popen([sys.executable, "-m", "asp.bench.mesh",
                             json.dumps(listen), json.dumps(connect), name],
                            stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True)


def _ready(process: subprocess.Popen[str]) -> tuple[float, list[str]]:
    """Wait for a peer's ``ready``; returns the Unix time [s] it came and the endpoints the
    peer listens on."""
    assert process.stdout is not None
    words = process.stdout.readline().split()
    if words[:1] != ["ready"]:
        raise RuntimeError("a bench peer did not start")
    return time.time(), words[1:]


def one_run(topology: str) -> dict:
    """B's view of A in one run of ``topology``: ``token`` (seen), ``query`` (answered), ``delay_ms``."""
    listen = [LOOPBACK_ANY_PORT] if topology != "star" else []
    planner = None
    if topology == "apart":
        a, b = _start([LOOPBACK_ANY_PORT], [], "A"), _start([LOOPBACK_ANY_PORT], [], "B")
        a_ports, b_ports = _ready(a)[1], _ready(b)[1]
        last = time.time()
        planner = open_session(connect=[*a_ports[:1], *b_ports[:1]])
    else:
        planner = open_session(listen=[LOOPBACK_ANY_PORT])
        planner_port = bound_endpoints(planner, [LOOPBACK_ANY_PORT])[0]
        a = _start(listen, [planner_port], "A")
        if topology != "together":
            _ready(a)
        b = _start(listen, [planner_port], "B")
        last = _ready(b)[0]
        if topology == "together":
            _ready(a)
    time.sleep(WATCH_S)
    for process in (a, b):  # both query while both are up
        assert process.stdin is not None
        process.stdin.write("report\n")
        process.stdin.flush()
    reports = [json.loads(p.stdout.readline()) for p in (a, b) if p.stdout is not None]
    for process in (a, b):
        process.communicate(timeout=30)
    planner.close()
    seen_a = reports[1]["seen"].get("A")
    return {"token": seen_a is not None, "query": "A" in reports[1]["answered"],
            "delay_ms": None if seen_a is None else max(0.0, 1000 * (seen_a - last))}


def main(argv: list[str]) -> int:
    parser = ArgumentParser(prog="bench mesh", description=__doc__.split("\n\n")[0])
    parser.add_argument("--repeat", type=int_in(1, 100), default=5, help="runs per topology (default 5)")
    parser.add_argument("--json", action="store_true", help="print JSON")
    args = parser.parse_args(argv)
    rows = []
    for topology in TOPOLOGIES:
        runs = [one_run(topology) for _ in range(args.repeat)]
        delays = [r["delay_ms"] for r in runs if r["delay_ms"] is not None]
        rows.append({"topology": topology, "runs": len(runs), "token": sum(r["token"] for r in runs),
                     "query": sum(r["query"] for r in runs),
                     "median_delay_ms": round(statistics.median(delays), 1) if delays else None,
                     "max_delay_ms": round(max(delays), 1) if delays else None})
    if args.json:
        print(json.dumps({"zenoh": version("eclipse-zenoh"), "rows": rows}))
        return 0
    print(f"eclipse-zenoh {version('eclipse-zenoh')}, {args.repeat} run(s) per topology")
    print(f"{'topology':<12} {'B sees A token':>14} {'B query reaches A':>17} {'delay median [ms]':>17} {'max':>7}")
    for r in rows:
        print(f"{r['topology']:<12} {r['token']:>10}/{r['runs']:<3} {r['query']:>13}/{r['runs']:<3} "
              f"{r['median_delay_ms'] if r['median_delay_ms'] is not None else '-':>17} "
              f"{r['max_delay_ms'] if r['max_delay_ms'] is not None else '-':>7}")
    return 0


if __name__ == "__main__":
    peer(json.loads(sys.argv[1]), json.loads(sys.argv[2]), sys.argv[3])
