"""``./run.sh bench session``: the bridge's overhead and the session's wall time.

1. Request/reply over Zenoh on loopback with a ``truth`` cell (no simulation): a
   validated InsertRequest → InsertReply round trip (encode, size cap, decode and
   validate on both sides, idempotency cache) beside a bare Zenoh query round trip of
   the same payload to the cell's ``ping`` queryable, measured alternately in the same
   run; medians [ms] and their ratio. Target: validated median < 1 ms.
2. The Cranfield session (``sim`` backend, or ``--backend truth --delay S``: experiments
   that take S seconds without using the cores) with 1 cell and with 2 cells: wall time [s]
   of the whole command, experiments, the share of the learning time the cells were busy
   with experiments (1.0: never idle), and the ratio 2 cells / 1 cell (target ≤ 0.65;
   on a shared 2-core machine the cells compete with everything else for the cores, so
   the sessions run in pairs, 1 cell then 2 cells back to back, and each pair's ratio
   is reported beside the ratio of the medians).
3. ``--product N --cell-counts 1,2,4,8``: load. Sessions with 1, 2, 4, 8 ``truth`` cells (each
   experiment takes ``--delay`` seconds without using the cores) on a generated N×N
   product (:mod:`asp.bench.products`): wall time [s] of the whole command, the learning
   time [s] (from the cells being ready to the last result, ``session.json`` timings), the
   speed-up of each against 1 cell, experiments and their ratio to the 1-cell run,
   duplicates (a request journaled twice, or a pair run again though not a re-test; must
   be 0) and the planner's time per experiment [ms] (recording results and choosing the
   next ones). Targets on 20×20 at ``--delay 0.5``: 8 cells at least 6x faster than 1,
   with at most 10 % more experiments.
4. ``--hosts K``: the Cranfield session with K cells on loopback (started by the session),
   then with K cells in K network namespaces joined only through ``./run.sh router``
   (:mod:`asp.session.hosts`; needs root): each run's figures and the ratio of their
   learning times.
"""

from __future__ import annotations

import argparse
import json
import os
import queue
import statistics
import subprocess
import sys
import tempfile
import time
from collections import Counter
from pathlib import Path

import zenoh

from asp import MAX_IDS, PlannerError
from asp.bench.products import write_product
from asp.session.cells import ROOT, start_cell, stop_all
from asp.session.hosts import CLIENT_CONFIG, Hosts, unavailable
from asp.session.journal import JOURNAL_NAME, JournalEntry, read_journal
from asp.session.settings import MAX_CELLS
from asp.sizes.policies import policy_names
from bridge.cell_settings import ServeSettings
from bridge.cli_types import MAX_SEED, ArgumentParser, comma_list, finite_float, int_in, number_in
from bridge.client import CellDirectory, request_insert
from bridge.keys import ping_key
from bridge.messages import InsertRequest, encode
from bridge.session import LOOPBACK_ANY_PORT, bound_endpoints, open_session

MAX_HOSTS = 16
"""--hosts: at most this many cell namespaces."""


def _payload(reply: zenoh.Reply) -> bytes:
    """The payload of a ping's reply; an error reply is a failed benchmark."""
    if reply.ok is None:
        raise PlannerError(f"ping failed: {reply.err}")
    return reply.ok.payload.to_bytes()


def _ms(values: list[float]) -> dict[str, float]:
    ordered = sorted(values)
    return {"median_ms": round(1000 * statistics.median(ordered), 4),
            "p90_ms": round(1000 * ordered[int(0.9 * (len(ordered) - 1))], 4)}


def round_trips(count: int) -> dict:
    """Validated insert round trips vs bare queries, alternating, to one truth cell."""
    session = open_session(listen=[LOOPBACK_ANY_PORT])
    cell = start_cell(ServeSettings(cell_id="bench", backend="truth",
                                    connect=tuple(bound_endpoints(session, [LOOPBACK_ANY_PORT])[:1])))
    try:
        CellDirectory(session).wait_for(1, timeout=30)
        replies: queue.SimpleQueue[bytes] = queue.SimpleQueue()
        validated: list[float] = []
        bare: list[float] = []
        for k in range(count + 20):  # the first 20 of each warm up
            request = InsertRequest(id=f"bench-{k}", part="p3", hole="s1", seed=k)
            payload = encode(request)
            t0 = time.perf_counter()
            session.get(ping_key("bench"), lambda reply: replies.put(_payload(reply)),
                        payload=payload, timeout=10.0)
            replies.get(timeout=15.0)
            t1 = time.perf_counter()
            request_insert(session, "bench", request, timeout=10.0)
            t2 = time.perf_counter()
            if k >= 20:
                bare.append(t1 - t0)
                validated.append(t2 - t1)
        timed, untimed = _ms(validated), _ms(bare)
        return {"round_trips": count, "payload_bytes": len(payload), "validated": timed, "bare": untimed,
                "ratio": round(timed["median_ms"] / untimed["median_ms"], 3)}
    finally:
        session.close()
        cell.stop()


def session_run(cells: int, policy: str, backend: str, delay_s: float, assembly: str = "cranfield",
                hosts: Hosts | None = None, client_config: Path | None = None) -> dict:
    """One ``session --cells N`` command: wall time [s], experiments, cell busy share,
    duplicates, learning and planning time (see the module doc). With ``hosts``, the
    planner runs in the router namespace and uses the N cells already started in the cell
    namespaces (:meth:`Hosts.start_fleet`, Zenoh clients by ``client_config``) instead."""
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    with tempfile.TemporaryDirectory() as tmp:
        argv = [sys.executable, "-m", "assembly_constraints", "session", "--assembly", assembly,
                "--policy", policy, "--out", str(Path(tmp) / "run"), "--json",
                "--backend", backend, "--delay", str(delay_s)]
        if hosts is None:
            argv += ["--cells", str(cells)]
        else:
            argv = hosts.argv(hosts.router, [*argv, "--cells", "0", "--zenoh-config", str(client_config),
                                             "--connect", hosts.router_endpoints()[0],
                                             "--allow-cells", ",".join(f"c{k}" for k in range(1, cells + 1))])
        t0 = time.perf_counter()
        done = subprocess.run(argv, cwd=ROOT, env=env, capture_output=True, text=True, timeout=900)
        wall = time.perf_counter() - t0
        if done.returncode != 0:
            raise SystemExit(f"session --cells {cells} failed: {done.stderr.strip()}")
        result = json.loads(done.stdout)
        if not result["matches_truth"]:
            raise SystemExit(f"session --cells {cells} learned a wrong relation")
        entries = read_journal(Path(tmp) / "run" / JOURNAL_NAME)
        busy = cell_busy_fraction(entries, cells)
        timings = json.loads((Path(tmp) / "run" / "session.json").read_text(encoding="utf-8"))["timings"]
    return {"wall_s": round(wall, 2), "experiments": result["experiments"], "cell_busy": busy,
            "duplicates": duplicates(entries),
            "learning_s": round(timings["learned_s"] - timings["cells_ready_s"], 2),
            "planning_s": timings["planning_s"],
            "planning_ms_per_experiment": round(1000 * timings["planning_s"] / result["experiments"], 1)}


def hosts_runs(count: int, policy: str, backend: str, delay_s: float) -> dict:
    """The Cranfield session with ``count`` cells on loopback (started by the session), then
    with ``count`` cells in network namespaces of their own joined through the router
    (:mod:`asp.session.hosts`): each run's figures and the ratio of the learning times."""
    why_not = unavailable()
    if why_not is not None:
        raise PlannerError(f"--hosts: {why_not}")
    loopback = session_run(count, policy, backend, delay_s)
    with tempfile.TemporaryDirectory() as tmp, Hosts(count) as hosts:
        client = Path(tmp) / "client.json5"
        client.write_text(CLIENT_CONFIG, encoding="utf-8")
        fleet = hosts.start_fleet(client, backend=backend, delay_s=delay_s)
        try:
            namespaces = session_run(count, policy, backend, delay_s, hosts=hosts, client_config=client)
        finally:
            stop_all(fleet)
    return {"hosts": count, "backend": backend, "delay_s": delay_s, "loopback": loopback, "namespaces": namespaces,
            "learning_ratio": round(namespaces["learning_s"] / loopback["learning_s"], 3)}


def duplicates(entries: list[JournalEntry]) -> int:
    """Journal entries that repeat a request id, or a pair without being a re-test."""
    ids = Counter(e.id for e in entries)
    first_runs = Counter((e.part, e.hole) for e in entries if not e.retest)
    return sum(n - 1 for n in ids.values()) + sum(n - 1 for n in first_runs.values())


def load_runs(product: int, cell_counts: list[int], policy: str, delay_s: float, seed: int) -> dict:
    """Sessions on a generated ``product``×``product`` assembly with each cell count."""
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp) / f"product{product}"
        write_product(folder, product, seed)
        runs = [{"cells": n, **session_run(n, policy, "truth", delay_s, str(folder))} for n in cell_counts]
    base = runs[0]
    for run in runs:
        run["speedup"] = round(base["wall_s"] / run["wall_s"], 2)
        run["learning_speedup"] = round(base["learning_s"] / run["learning_s"], 2)
        run["experiments_ratio"] = round(run["experiments"] / base["experiments"], 3)
    return {"product": f"{product}x{product}", "delay_s": delay_s, "seed": seed, "runs": runs}


def session_walls(repeat: int, policy: str, backend: str, delay_s: float) -> dict:
    """``repeat`` pairs of sessions, 1 cell then 2 cells back to back (both see about the
    same load of a shared machine): per cell count the walls and their median, and the
    ratio 2 cells / 1 cell of every pair and of the medians."""
    runs: dict[int, list[dict]] = {1: [], 2: []}
    for _ in range(repeat):
        for cells in runs:
            runs[cells].append(session_run(cells, policy, backend, delay_s))
    sessions = [{"cells": cells, "walls_s": [r["wall_s"] for r in rs],
                 "median_wall_s": round(statistics.median(r["wall_s"] for r in rs), 2),
                 "experiments": [r["experiments"] for r in rs],
                 "cell_busy": [r["cell_busy"] for r in rs]} for cells, rs in runs.items()]
    pairs = [round(two["wall_s"] / one["wall_s"], 3) for one, two in zip(runs[1], runs[2])]
    return {"sessions": sessions, "pair_ratios": pairs,
            "median_pair_ratio": round(statistics.median(pairs), 3),
            "ratio_2_over_1": round(sessions[1]["median_wall_s"] / sessions[0]["median_wall_s"], 3)}


def cell_busy_fraction(entries: list[JournalEntry], cells: int) -> float:
    """Share of the learning span [first start, last end] the cells spent on experiments."""
    start = min(e.time - e.wall_s for e in entries)
    end = max(e.time for e in entries)
    return round(sum(e.wall_s for e in entries) / (cells * (end - start)), 3)


def main(argv: list[str]) -> int:
    parser = ArgumentParser(prog="bench session", description=__doc__.split("\n\n")[0])
    parser.add_argument("--round-trips", type=int_in(1, 10**6), default=1000, help="per kind (default 1000)")
    parser.add_argument("--repeat", type=int_in(1, 100), default=1,
                        help="pairs of sessions, 1 cell then 2 cells back to back (default 1)")
    parser.add_argument("--quick", action="store_true", help="100 round trips per kind")
    parser.add_argument("--policy", default="best", choices=policy_names(), help="session policy (default best)")
    parser.add_argument("--backend", choices=("sim", "truth"), default="sim",
                        help="cells of the sessions (default sim)")
    parser.add_argument("--delay", type=finite_float(0, 3600), default=0.0, metavar="S",
                        help="truth backend: seconds per experiment, e.g. 2 to see the "
                        "parallel speed-up without competing for the cores")
    parser.add_argument("--skip-sessions", action="store_true", help="only the round trips")
    parser.add_argument("--product", type=int_in(2, MAX_IDS), metavar="N",
                        help="load: sessions on a generated NxN product instead (truth cells, --delay)")
    parser.add_argument("--cell-counts", type=comma_list(number_in(int, 1, MAX_CELLS + 1),
                                                         f"cell counts in [1, {MAX_CELLS}]"),
                        default=[1, 2, 4, 8], metavar="N,...",
                        help="with --product: one session per count, as session --cells N (default 1,2,4,8)")
    parser.add_argument("--seed", type=int_in(0, MAX_SEED), default=1,
                        help="with --product: seed of the product (default 1)")
    parser.add_argument("--hosts", type=int_in(1, MAX_HOSTS), metavar="K",
                        help="the Cranfield session with K cells in K network namespaces joined through "
                             "the router, next to K cells on loopback (needs root)")
    parser.add_argument("--json", action="store_true", help="print JSON")
    args = parser.parse_args(argv)
    if args.product is not None:
        return _load(args)
    if args.hosts is not None:
        return _hosts(args)
    figures: dict = {"overhead": round_trips(100 if args.quick else args.round_trips)}
    o = figures["overhead"]
    if not args.json:
        print(f"round trip over Zenoh on loopback ({o['round_trips']} each, "
              f"{o['payload_bytes']} B): validated insert median {o['validated']['median_ms']:.3f} ms "
              f"(p90 {o['validated']['p90_ms']:.3f}), bare query median {o['bare']['median_ms']:.3f} ms "
              f"(p90 {o['bare']['p90_ms']:.3f}), ratio {o['ratio']:.2f}", flush=True)
    if not args.skip_sessions:
        figures.update(session_walls(args.repeat, args.policy, args.backend, args.delay))
        if not args.json:
            for s in figures["sessions"]:
                print(f"Cranfield session, {s['cells']} cell(s), {args.backend}: median {s['median_wall_s']:.1f} s "
                      f"wall (runs {s['walls_s']}, experiments {s['experiments']}, cells busy "
                      f"{s['cell_busy']} of the learning time)")
            print(f"ratio 2 cells / 1 cell: {figures['ratio_2_over_1']:.2f} (of the medians); "
                  f"per pair run back to back {figures['pair_ratios']}, median {figures['median_pair_ratio']:.2f}")
    if args.json:
        print(json.dumps(figures, indent=2))
    return 0


def _load(args: argparse.Namespace) -> int:
    figures = load_runs(args.product, [int(n) for n in args.cell_counts], args.policy, args.delay, args.seed)
    if args.json:
        print(json.dumps(figures, indent=2))
        return 0
    print(f"{figures['product']} product (seed {args.seed}), truth cells, {args.delay} s per experiment, "
          f"policy {args.policy}")
    print(f"{'cells':>5} {'wall [s]':>9} {'speed-up':>8} {'learning [s]':>12} {'speed-up':>8} {'experiments':>11} "
          f"{'ratio':>6} {'duplicates':>10} {'busy':>5} {'planning/exp [ms]':>17}")
    for r in figures["runs"]:
        print(f"{r['cells']:>5} {r['wall_s']:>9.1f} {r['speedup']:>8.2f} {r['learning_s']:>12.1f} "
              f"{r['learning_speedup']:>8.2f} {r['experiments']:>11} {r['experiments_ratio']:>6.3f} "
              f"{r['duplicates']:>10} {r['cell_busy']:>5.2f} {r['planning_ms_per_experiment']:>17.1f}")
    return 0


def _hosts(args: argparse.Namespace) -> int:
    figures = hosts_runs(args.hosts, args.policy, args.backend, args.delay)
    if args.json:
        print(json.dumps(figures, indent=2))
        return 0
    print(f"Cranfield session, {args.hosts} {args.backend} cell(s), {args.delay} s per experiment, "
          f"policy {args.policy}")
    for where in ("loopback", "namespaces"):
        r = figures[where]
        print(f"{where:>10}: learning {r['learning_s']:.1f} s, wall {r['wall_s']:.1f} s, {r['experiments']} "
              f"experiments, cells busy {r['cell_busy']:.2f}, duplicates {r['duplicates']}")
    print(f"learning time, namespaces / loopback: {figures['learning_ratio']:.2f}")
    return 0
