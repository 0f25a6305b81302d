"""Real cell processes on loopback (truth backend): refusals, idempotency, failover."""

from __future__ import annotations

import json
import queue
import signal
import threading
import time
from collections.abc import Iterator

import pytest
import zenoh

from asp.bench.mesh import main as bench_mesh
from asp.session.cells import CellProcess, start_cell
from bridge.cell_settings import ServeSettings
from bridge.client import (
    CellConflict,
    CellDirectory,
    CellPool,
    CellRefused,
    CellTimeout,
    PoolLimits,
    check_echo,
    request_insert,
    send_insert,
)
from bridge.keys import alive_key
from bridge.messages import (
    MAX_COUNT,
    MAX_MESSAGE_BYTES,
    MAX_REQUEST_ID,
    ErrorReply,
    InsertReply,
    InsertRequest,
    MessageError,
    decode_reply,
    decode_request,
    encode,
)
from bridge.session import free_loopback_endpoint, open_session
from executor.serve.node import QUEUE_SIZE

pytestmark = pytest.mark.timeout(60)


@pytest.fixture
def network() -> Iterator[tuple[str, zenoh.Session, CellDirectory, list[CellProcess]]]:
    """A planner-side session listening on a free loopback port; cells are added by tests."""
    endpoint = free_loopback_endpoint()
    session = open_session(listen=(endpoint,))
    directory = CellDirectory(session)
    cells: list[CellProcess] = []
    try:
        yield endpoint, session, directory, cells
    finally:
        for cell in cells:
            cell.kill()
        directory.close()
        session.close()


@pytest.fixture(scope="module")
def served(tmp_path_factory: pytest.TempPathFactory) -> Iterator[tuple[str, zenoh.Session, CellDirectory,
                                                                      CellProcess]]:
    """A planner-side session listening on a free loopback port and one truth cell c1 on it,
    recording to Rerun, shared by the tests that leave c1 serving (one cell start for them
    all; each uses request ids of its own, as the cell caches replies by id)."""
    endpoint = free_loopback_endpoint()
    session = open_session(listen=(endpoint,))
    directory = CellDirectory(session)
    cell = start_cell(ServeSettings(cell_id="c1", backend="truth", connect=(endpoint,),
                                    rrd=str(tmp_path_factory.mktemp("served") / "c1.rrd"), recording_id="served"))
    try:
        directory.wait_for(1, timeout=20)
        yield endpoint, session, directory, cell
    finally:
        cell.kill()
        directory.close()
        session.close()


def raw_query(session: zenoh.Session, key: str, payload: bytes) -> InsertReply | ErrorReply:
    box: queue.SimpleQueue[bytes] = queue.SimpleQueue()
    session.get(key, lambda reply: box.put(reply.ok.payload.to_bytes()), payload=payload,
                timeout=10.0)
    return decode_reply(box.get(timeout=15.0))


@pytest.mark.slow
def test_bad_requests_get_error_replies_and_the_cell_keeps_serving(served) -> None:
    endpoint, session, directory, cell = served
    bad = {
        b"x" * 100_000: "oversized",
        b"\xff\xfe not json": "malformed",
        b'{"kind":"insert","id":"a1","part":"__import__","hole":"r1"}': "malformed",
        b'{"kind":"insert","id":"a1","part":"p1","hole":"r1","v":99}': "version",
    }
    for payload, code in bad.items():
        reply = raw_query(session, "cell/c1/insert", payload)
        assert isinstance(reply, ErrorReply) and reply.code == code
    with pytest.raises(CellRefused, match="unknown_id"):
        request_insert(session, "c1", InsertRequest(id="u1", part="zz", hole="r1"), timeout=10)
    assert request_insert(session, "c1", InsertRequest(id="ok1", part="sh", hole="br"), 10).result == "fit"
    assert request_insert(session, "c1", InsertRequest(id="ok2", part="sh", hole="r1"), 10).result == "no_fit"
    assert cell.popen.poll() is None


@pytest.mark.slow
def test_a_cell_recording_to_rerun_refuses_a_huge_experiment_number_and_keeps_serving(served) -> None:
    """The bounds of ``tests/bridge/test_message_bounds.py`` at a real cell: a request at
    them is answered, one past them (an experiment number of 2**63 or 10**30) refused with
    an error reply."""
    endpoint, session, directory, cell = served
    for number in (2**63, 10**30, -1):
        payload = b'{"kind":"insert","id":"n%d","part":"sh","hole":"br","experiment":%d}' % (abs(number), number)
        reply = raw_query(session, "cell/c1/insert", payload)
        assert isinstance(reply, ErrorReply) and reply.code == "malformed", reply
        assert "at `$.experiment`" in reply.error
    at_bounds = InsertRequest(id="x" * MAX_REQUEST_ID, part="sh", hole="br", experiment=MAX_COUNT, seed=2**32 - 1)
    answer = request_insert(session, "c1", at_bounds, timeout=10)
    assert isinstance(answer, InsertReply) and answer.result == "fit"
    assert request_insert(session, "c1", InsertRequest(id="after", part="sh", hole="r1"), 10).result == "no_fit"
    assert cell.popen.poll() is None


@pytest.mark.slow
def test_a_repeated_id_returns_the_cached_reply_without_rerunning(served) -> None:
    endpoint, session, directory, cell = served
    request = InsertRequest(id="same", part="p3", hole="s1")
    first = request_insert(session, "c1", request, timeout=10)
    again = request_insert(session, "c1", request, timeout=10)
    assert first == again  # same wall_s: the experiment was not run again
    cell.wait_for_line("done same", timeout=5)
    assert sum(line.startswith("start same") for line in cell.lines) == 1


@pytest.mark.slow
def test_a_cell_killed_mid_experiment_loses_no_request_and_counts_none_twice(network) -> None:
    endpoint, session, directory, cells = network
    # c1 slow enough to be killed in an experiment; c2, which runs the rest, quicker
    for cell_id, delay in (("c1", 0.5), ("c2", 0.2)):
        cells.append(start_cell(ServeSettings(cell_id=cell_id, backend="truth", connect=(endpoint,), delay_s=delay)))
    directory.wait_for(2, timeout=20)
    pairs = [(p, h) for p in ("p1", "p3", "sh") for h in ("r1", "s1", "br")]
    requests = [InsertRequest(id=f"r{i}", part=p, hole=h) for i, (p, h) in enumerate(pairs)]
    delivered: list[tuple[str, str]] = []

    def kill_c1_in_its_second_experiment() -> None:
        cells[0].wait_for_line("start", timeout=30, count=2)
        cells[0].kill()

    killer = threading.Thread(target=kill_c1_in_its_second_experiment)
    killer.start()
    pool = CellPool(session, directory, PoolLimits(timeout=20.0, wait_for_cell=20.0))
    for request in requests:
        pool.submit(request)
    replies: dict[str, InsertReply] = {}
    while pool.unfinished:
        request, reply = pool.next_reply()
        replies[request.id] = reply
        delivered.append((request.id, reply.cell))
    pool.close()
    killer.join(30)
    assert sorted(replies) == sorted(r.id for r in requests)
    assert len(delivered) == len(requests) == len({rid for rid, _ in delivered})
    truth = {("p1", "r1"), ("p1", "s1"), ("p1", "br"), ("p3", "s1"), ("p3", "br"), ("sh", "br")}
    for request in requests:
        assert replies[request.id].result == ("fit" if (request.part, request.hole) in truth else "no_fit")
    started_on_c1 = {line.split()[1] for line in cells[0].lines if line.startswith("start")}
    finished_on_c1 = {rid for rid, cell in delivered if cell == "c1"}
    lost = started_on_c1 - finished_on_c1
    assert lost, "c1 was killed mid-experiment"
    assert all(replies[rid].cell == "c2" for rid in lost)


@pytest.mark.slow
def test_with_no_cell_left_the_pool_waits_for_a_new_one(network) -> None:
    endpoint, session, directory, cells = network
    cells.append(start_cell(ServeSettings(cell_id="c1", backend="truth", connect=(endpoint,), delay_s=0.5)))
    directory.wait_for(1, timeout=20)

    def replace_c1_in_its_second_experiment() -> None:
        cells[0].wait_for_line("start", timeout=30, count=2)
        cells[0].kill()
        cells.append(start_cell(ServeSettings(cell_id="c2", backend="truth", connect=(endpoint,))))

    replacer = threading.Thread(target=replace_c1_in_its_second_experiment)
    replacer.start()
    pool = CellPool(session, directory, PoolLimits(timeout=20.0, wait_for_cell=30.0))
    requests = [InsertRequest(id=f"w{i}", part="p1", hole=h) for i, h in enumerate(("r1", "s1", "br"))]
    for request in requests:
        pool.submit(request)
    cells_of = {}
    while pool.unfinished:
        request, reply = pool.next_reply()
        cells_of[request.id] = reply.cell
    pool.close()
    replacer.join(30)
    assert cells_of == {"w0": "c1", "w1": "c2", "w2": "c2"}


@pytest.mark.slow
def test_a_reused_id_with_another_pair_is_refused_not_answered_from_the_cache(served) -> None:
    endpoint, session, directory, cell = served
    assert request_insert(session, "c1", InsertRequest(id="r", part="sh", hole="br"), 10).result == "fit"
    with pytest.raises(CellRefused, match="id_reused"):
        request_insert(session, "c1", InsertRequest(id="r", part="sh", hole="r1"), timeout=10)
    bad_utf8 = b'{"kind":"insert","id":"u","part":"p1","hole":"r\xff1"}'
    reply = raw_query(session, "cell/c1/insert", bad_utf8)
    assert isinstance(reply, ErrorReply) and reply.code == "malformed"
    echoed = raw_ping(session, "cell/c1/ping", b"x" * 100_000)
    assert len(echoed) == MAX_MESSAGE_BYTES


def raw_ping(session: zenoh.Session, key: str, payload: bytes) -> bytes:
    box: queue.SimpleQueue[bytes] = queue.SimpleQueue()
    session.get(key, lambda reply: box.put(reply.ok.payload.to_bytes()), payload=payload, timeout=10.0)
    return box.get(timeout=15.0)


@pytest.mark.slow
def test_a_full_queue_answers_busy_a_request_past_its_timeout_expires_and_sigterm_closes_the_cell(network) -> None:
    """Then SIGTERM closes the cell (exit code 0) and its token disappears."""
    endpoint, session, directory, cells = network
    cells.append(start_cell(ServeSettings(cell_id="c1", backend="truth", connect=(endpoint,), delay_s=0.3)))
    directory.wait_for(1, timeout=20)
    outcomes: queue.SimpleQueue[object] = queue.SimpleQueue()
    count = QUEUE_SIZE + 10
    for k in range(count):  # all at once: one runs, QUEUE_SIZE wait, the rest are refused
        send_insert(session, "c1", InsertRequest(id=f"q{k}", part="p1", hole="r1", timeout_s=0.5), 20.0,
                    outcomes.put)
    results = [outcomes.get(timeout=30) for _ in range(count)]
    codes = sorted(r.reply.code for r in results if isinstance(r, CellRefused))
    answered = [r for r in results if isinstance(r, InsertReply)]
    assert codes.count("busy") >= 1, codes
    assert codes.count("expired") >= 5, codes  # waited behind 0.3 s experiments longer than 0.5 s
    assert 1 <= len(answered) <= 4, codes
    cells[0].wait_for_line("start q", timeout=10, count=len(answered))  # its stdout is read by a thread
    assert sum(line.startswith("start q") for line in cells[0].lines) == len(answered)
    gone: queue.SimpleQueue[str] = queue.SimpleQueue()
    directory.listen(lambda cell, alive: None if alive else gone.put(cell))
    cells[0].popen.send_signal(signal.SIGTERM)
    assert cells[0].popen.wait(10) == 0
    assert gone.get(timeout=10) == "c1"


@pytest.mark.slow
def test_a_reply_that_does_not_echo_the_request_or_contradicts_another_is_never_taken(served) -> None:
    endpoint, session, directory, cell = served

    def liar(query: zenoh.Query) -> None:  # a second process answering for c1: "fit", for p9
        request = decode_request(query.payload.to_bytes())
        query.reply(query.key_expr, encode(InsertReply(id=request.id, cell="c1", part="p9", hole=request.hole,
                                                       result="fit")))

    rogue = open_session(connect=(endpoint,))
    try:
        declared = rogue.declare_queryable("cell/c1/insert", liar)
        time.sleep(0.5)  # the declaration reaches the planner's session
        with pytest.raises(MessageError, match="does not echo"):
            check_echo(InsertReply(id="x", cell="c1", part="p9", hole="r1", result="fit"), "c1",
                       InsertRequest(id="x", part="p1", hole="r1"))
        reply = request_insert(session, "c1", InsertRequest(id="e1", part="sh", hole="r1"), timeout=10)
        assert (reply.part, reply.hole, reply.result) == ("sh", "r1", "no_fit")  # the liar's echo is wrong

        def contradicts(query: zenoh.Query) -> None:
            request = decode_request(query.payload.to_bytes())
            query.reply(query.key_expr, encode(InsertReply(id=request.id, cell="c1", part=request.part,
                                                           hole=request.hole, result="fit")))

        declared.undeclare()
        declared = rogue.declare_queryable("cell/c1/insert", contradicts)
        time.sleep(0.5)
        with pytest.raises(CellConflict, match="2 different replies"):
            request_insert(session, "c1", InsertRequest(id="e2", part="sh", hole="r1"), timeout=10)
        declared.undeclare()
    finally:
        rogue.close()


def test_a_token_with_nothing_behind_it_is_dropped_and_others_are_not_trusted(network) -> None:
    endpoint, session, directory, cells = network
    rogue = open_session(connect=(endpoint,))
    try:
        tokens = [rogue.liveliness().declare_token(alive_key(cell)) for cell in ("c1", "evil")]
        directory.wait_for(2, timeout=20)
        pool = CellPool(session, directory, PoolLimits(timeout=1.0, wait_for_cell=1.0, max_misses=2), allowed={"c1"})
        pool.submit(InsertRequest(id="t1", part="p1", hole="r1"))
        started = time.monotonic()
        with pytest.raises(CellTimeout, match="no cell alive"):
            pool.next_reply()
        assert time.monotonic() - started < 6.0  # two missed replies, then wait_for_cell
        assert "cell c1 dropped after 2 missed replies" in pool.incidents
        assert not any("evil" in incident for incident in pool.incidents)
        pool.close()
        del tokens
    finally:
        rogue.close()


def _refusal(cell: CellProcess) -> str:
    """The one line a cell that refused its id printed; asserts it exited with code 2 before ``ready``."""
    assert cell.popen.wait(30) == 2
    cell.wait_for_line("error:", 5)
    assert not any(line.startswith("ready") for line in cell.lines), cell.lines
    errors = [line for line in cell.lines if line.startswith("error:")]
    assert len(errors) == 1 and len(cell.lines) == 1, cell.lines
    return errors[0]


@pytest.mark.slow  # two or three cell processes
def test_a_second_process_on_a_served_cell_id_refuses_to_start(served) -> None:
    endpoint, session, directory, cell = served
    second = CellProcess(ServeSettings(cell_id="c1", backend="truth", connect=(endpoint,)))
    try:
        assert "error: cell id c1 is already served by another process" in _refusal(second)
    finally:
        second.kill()
    assert cell.popen.poll() is None and directory.duplicated == set()  # the planner never saw it
    assert request_insert(session, "c1", InsertRequest(id="d1", part="sh", hole="br"), 10).result == "fit"


@pytest.mark.slow  # two or three cell processes
def test_two_processes_started_together_on_one_id_leave_exactly_one(network) -> None:
    endpoint, session, directory, cells = network
    cells += [CellProcess(ServeSettings(cell_id="c1", backend="truth", connect=(endpoint,))) for _ in range(2)]
    deadline = time.monotonic() + 40
    while all(cell.popen.poll() is None for cell in cells) and time.monotonic() < deadline:
        time.sleep(0.1)
    refused = [cell for cell in cells if cell.popen.poll() is not None]
    assert len(refused) == 1 and "cell id c1" in _refusal(refused[0])
    directory.wait_for(1, timeout=20)
    assert request_insert(session, "c1", InsertRequest(id="d2", part="sh", hole="br"), 10).result == "fit"


@pytest.mark.slow  # two or three cell processes
def test_cells_on_one_id_that_meet_later_leave_the_older_serving(network) -> None:
    endpoint, session, directory, cells = network
    first, second = free_loopback_endpoint(), free_loopback_endpoint()
    cells.append(start_cell(ServeSettings(cell_id="c1", backend="truth", listen=(first,))))
    # apart: no peer connects them
    cells.append(start_cell(ServeSettings(cell_id="c1", backend="truth", listen=(second,))))
    late = open_session(connect=[first, second])  # a planner joins both: Zenoh's gossip connects them
    try:
        assert cells[1].popen.wait(30) == 2 and cells[0].popen.poll() is None
        assert "error: cell id c1 is already served" in cells[1].wait_for_line("error:", 5)
        assert request_insert(late, "c1", InsertRequest(id="d3", part="sh", hole="br"), 10).result == "fit"
    finally:
        late.close()


@pytest.mark.slow
def test_a_token_of_a_second_claimant_the_cells_cannot_see_makes_the_planner_wait(served) -> None:
    """The planner's own guard: two tokens on one id (here a peer that listens nowhere, so
    the cell cannot meet it) and that id gets nothing until one is gone."""
    endpoint, session, directory, cell = served
    hidden = open_session(connect=(endpoint,))
    try:
        token = hidden.liveliness().declare_token(alive_key("c1", "hidden"))
        deadline = time.monotonic() + 20
        while "c1" in directory.alive() and time.monotonic() < deadline:
            time.sleep(0.1)
        assert directory.alive() == set() and directory.duplicated == {"c1"}
        token.undeclare()
        directory.wait_for(1, timeout=20)  # one claimant left: usable again
        assert request_insert(session, "c1", InsertRequest(id="d4", part="sh", hole="br"), 10).result == "fit"
    finally:
        hidden.close()


@pytest.mark.slow  # three peer processes
def test_bench_mesh_sees_two_listening_peers_meet(monkeypatch: pytest.MonkeyPatch,
                                                  capsys: pytest.CaptureFixture[str]) -> None:
    """``./run.sh bench mesh`` on its row of how cells start (A and B connect to the
    planner and listen on a port of their own): B sees A's token and B's query reaches A,
    watched 0.5 s in place of 3. The other rows' meetings are the cells' above (started
    together; apart, joined by a planner later)."""
    monkeypatch.setattr("asp.bench.mesh.TOPOLOGIES", ("star+listen",))
    monkeypatch.setattr("asp.bench.mesh.WATCH_S", 0.5)
    assert bench_mesh(["--repeat", "1", "--json"]) == 0
    rows = json.loads(capsys.readouterr().out)["rows"]
    assert [(row["topology"], row["token"], row["query"]) for row in rows] == [("star+listen", 1, 1)], rows
