"""A corpus of bad input for both command lines (repository level: it spans the packages).

One row per case: ``(id, argv, setup, expected exit code, a word the message must hold)``.
``argv`` starting with ``executor`` runs ``python -m executor``, ``bench executor`` runs
``python -m executor.campaign.bench`` (as run.sh does), anything else ``python -m asp.cli``;
both run as separate processes in ``tmp_path``. ``setup`` is None, a dict of input files
(name → text or bytes) or a callable ``setup(tmp_path)``. Every bad input must give one
line ``error: ...`` on stderr holding the word, the exit code, and never a traceback.

Rows expecting :data:`EXIT_BROKEN_PIPE` run as ``... | head -1``: stdout is closed after
its first line, and stderr must stay empty.

Unreadable files: ``chmod 000`` does not stop root (the tests may run as root), so under
root the file is replaced by a symbolic link to ``/proc/self/mem``, a regular file whose
read fails with an I/O error for every user (checked; the case is skipped otherwise).
"""

from __future__ import annotations

import os
import shutil
import subprocess
from collections.abc import Callable
from pathlib import Path

import pytest

from asp.session.journal import MAX_JOURNAL_BYTES
from bridge.cli_types import EXIT_BROKEN_PIPE
from tests.conftest import ROOT, child_env, python_argv

CRANFIELD = ROOT / "data" / "cranfield"
TASKBOARD = ROOT / "data" / "taskboard"
Setup = Callable[[Path], None] | dict[str, str | bytes] | None


def unreadable(name: str, source: Path | None = None, text: str = "") -> Callable[[Path], None]:
    """Setup: ``name`` (a copy of ``source``, else ``text``) made unreadable (see the module doc)."""

    def setup(tmp: Path) -> None:
        path = tmp / name
        path.parent.mkdir(parents=True, exist_ok=True)
        path.unlink(missing_ok=True)
        if os.geteuid() == 0:
            path.symlink_to("/proc/self/mem")
        else:
            path.write_bytes(source.read_bytes() if source else text.encode())
            path.chmod(0)
        try:
            with path.open("rb") as file:
                file.read(1)
        except OSError:
            return
        pytest.skip(f"cannot make {name} unreadable here")

    return setup


def taskboard(**files: str) -> Callable[[Path], None]:
    """Setup: a copy of data/taskboard in ``asm/`` (without its assets), with ``files`` replaced."""

    def setup(tmp: Path) -> None:
        shutil.copytree(TASKBOARD, tmp / "asm", ignore=shutil.ignore_patterns("assets"))
        for name, content in files.items():
            (tmp / "asm" / name).write_text(content)

    return setup


def assembly(**files: str | bytes | Callable[[Path], None]) -> Callable[[Path], None]:
    """Setup: a copy of data/cranfield in ``asm/`` (without assets), with ``files``
    replaced (text, bytes, or a setup run with the copy's parent folder)."""

    def setup(tmp: Path) -> None:
        shutil.copytree(CRANFIELD, tmp / "asm", ignore=shutil.ignore_patterns("assets", "demonstrations"))
        for name, content in files.items():
            if callable(content):
                content(tmp)
            elif isinstance(content, bytes):
                (tmp / "asm" / name).write_bytes(content)
            else:
                (tmp / "asm" / name).write_text(content)

    return setup


def huge_journal(run: Path) -> None:
    """Setup: a run folder to resume whose journal is one byte over the bound (a sparse file)."""
    run.mkdir()
    (run / "session.json").write_text('{"assembly": "cranfield", "policy": "best", "seed": 0, "recording_id": "r"}')
    with (run / "journal.jsonl").open("wb") as file:
        file.truncate(MAX_JOURNAL_BYTES + 1)


CASES: list[tuple[str, tuple[str, ...], Setup, int, str]] = [
    # numeric options: finite, in range
    ("trial-seed-negative", ("executor", "trial", "--part", "p1", "--hole", "r1", "--seed", "-1"), None, 2, "--seed"),
    ("trial-trials-zero", ("executor", "trial", "--part", "p1", "--hole", "r1", "--trials", "0"), None, 2, "--trials"),
    ("session-timeout-negative", ("session", "--timeout", "-1"), None, 2, "--timeout"),
    ("session-timeout-nan", ("session", "--timeout", "nan"), None, 2, "finite"),
    ("session-wait-negative", ("session", "--wait-for-cell", "-1"), None, 2, "--wait-for-cell"),
    ("session-cells-huge", ("session", "--cells", "100000"), None, 2, "--cells"),
    ("session-plans-negative", ("session", "--plans", "-1"), None, 2, "--plans"),
    ("session-delay-nan", ("session", "--delay", "nan"), None, 2, "--delay"),
    ("session-confirm-huge", ("session", "--confirm", "99999999999"), None, 2, "--confirm"),
    ("session-seed-negative", ("session", "--seed", "-1"), None, 2, "--seed"),
    ("sizes-confirm-huge", ("sizes", "learn", "--assembly", "cranfield", "--confirm", "99999999999"), None, 2,
     "--confirm"),
    ("enumerate-limit-float", ("precedence", "enumerate", "--assembly", "cranfield", "--limit", "1e23"), None, 2,
     "--limit"),
    ("enumerate-limit-huge", ("precedence", "enumerate", "--assembly", "cranfield", "--limit", "1" + "0" * 23),
     None, 2, "--limit"),
    ("sample-n-negative", ("precedence", "sample", "--assembly", "cranfield", "-n", "-1"), None, 2, "-n"),
    ("plan-n-float", ("plan", "facts.lp", "-n", "1e20"), None, 2, "-n"),
    ("plan-n-huge", ("plan", "facts.lp", "-n", "1" + "0" * 20), None, 2, "-n"),
    ("plan-home-nan", ("plan", "facts.lp", "--optimal", "--assembly", "cranfield", "--home", "nan", "0"), None, 2,
     "--home"),
    ("plan-home-inf", ("plan", "facts.lp", "--optimal", "--assembly", "cranfield", "--home", "inf", "0"), None, 2,
     "--home"),
    ("plan-home-far", ("plan", "facts.lp", "--optimal", "--assembly", "cranfield", "--home", "1e12", "0"), None, 2,
     "--home"),
    ("plan-time-limit-negative", ("plan", "facts.lp", "--time-limit", "-1"), None, 2, "--time-limit"),
    ("assembly-position-nan", ("plan", "facts.lp", "--optimal", "--assembly", "asm"),
     assembly(**{"assembly.toml": (CRANFIELD / "assembly.toml").read_text().replace(
         "position = [0.55, -0.06]", "position = [nan, inf]", 1)}), 2, "finite"),
    # unreadable input files
    ("learn-unreadable-text", ("precedence", "learn", "d.txt"), unreadable("d.txt", CRANFIELD / "demos.txt"), 2,
     "read"),
    ("learn-unreadable-lp", ("precedence", "learn", "d.lp"), unreadable("d.lp", text="demo(1,1,a)."), 2, "read"),
    ("count-unreadable", ("precedence", "count", "p.lp"), unreadable("p.lp", CRANFIELD / "precedence.lp"), 2,
     "read"),
    ("enumerate-unreadable", ("precedence", "enumerate", "p.lp"), unreadable("p.lp", CRANFIELD / "precedence.lp"),
     2, "read"),
    ("sample-unreadable", ("precedence", "sample", "p.lp"), unreadable("p.lp", CRANFIELD / "precedence.lp"), 2,
     "read"),
    ("suggest-unreadable", ("precedence", "suggest", "d.txt"), unreadable("d.txt", CRANFIELD / "demos.txt"), 2,
     "read"),
    ("sizes-truth-unreadable", ("sizes", "learn", "--truth", "s.lp"), unreadable("s.lp", CRANFIELD / "sizes.lp"), 2,
     "read"),
    ("assign-unreadable", ("assign", "s.lp"), unreadable("s.lp", CRANFIELD / "sizes.lp"), 2, "read"),
    ("plan-unreadable", ("plan", "s.lp"), unreadable("s.lp", CRANFIELD / "sizes.lp"), 2, "read"),
    ("view-unreadable", ("view", "x.rrd", "--print"), unreadable("x.rrd", text="x"), 2, "read"),
    ("session-unreadable-assembly-toml", ("session", "--assembly", "asm"),
     assembly(**{"assembly.toml": unreadable("asm/assembly.toml", CRANFIELD / "assembly.toml")}), 2, "read"),
    ("session-unreadable-demos", ("session", "--assembly", "asm"),
     assembly(**{"demos.txt": unreadable("asm/demos.txt", CRANFIELD / "demos.txt")}), 2, "read"),
    ("session-unreadable-sizes", ("session", "--assembly", "asm"),
     assembly(**{"sizes.lp": unreadable("asm/sizes.lp", CRANFIELD / "sizes.lp")}), 2, "read"),
    ("session-unreadable-precedence", ("session", "--assembly", "asm"),
     assembly(**{"precedence.lp": unreadable("asm/precedence.lp", CRANFIELD / "precedence.lp")}), 2, "read"),
    ("trial-unreadable-geometry", ("executor", "trial", "--part", "p1", "--hole", "r1", "--assembly", "asm"),
     assembly(**{"geometry.toml": unreadable("asm/geometry.toml", CRANFIELD / "geometry.toml")}), 2, "read"),
    # session --resume with a damaged session.json: fails before any cell starts
    ("resume-empty", ("session", "--resume", "run"), {"run/session.json": ""}, 2, "JSON"),
    ("resume-binary", ("session", "--resume", "run"), {"run/session.json": b"\x00\xff\xfe{"}, 2, "JSON"),
    ("resume-list", ("session", "--resume", "run"), {"run/session.json": "[1, 2]"}, 2, "object"),
    ("resume-missing-keys", ("session", "--resume", "run"), {"run/session.json": "{}"}, 2, '"assembly"'),
    ("resume-wrong-types", ("session", "--resume", "run"),
     {"run/session.json": '{"assembly": "cranfield", "policy": "best", "seed": "x", "recording_id": "r"}'}, 2,
     '"seed"'),
    ("resume-bad-policy", ("session", "--resume", "run"),
     {"run/session.json": '{"assembly": "cranfield", "policy": 7, "seed": 0, "recording_id": "r"}'}, 2,
     '"policy"'),
    ("resume-bad-cell-options", ("session", "--resume", "run"),
     {"run/session.json": '{"assembly": "cranfield", "policy": "best", "seed": 0, "recording_id": "r", '
                          '"cell_options": ["--layer", "sideways"]}'}, 2, '"cell_options"'),
    ("resume-huge-journal", ("session", "--resume", "run"),
     lambda tmp: huge_journal(tmp / "run"), 2, "larger than"),
    # recordings, cell geometry
    ("view-garbage", ("view", "g.rrd", "--print"), {"g.rrd": bytes(range(256)) * 8}, 2, "Rerun recording"),
    ("view-empty", ("view", "e.rrd", "--print"), {"e.rrd": b""}, 2, "Rerun recording"),
    ("trial-binary-geometry", ("executor", "trial", "--part", "p1", "--hole", "r1", "--assembly", "asm"),
     assembly(**{"geometry.toml": bytes(range(256))}), 2, "geometry.toml"),
    ("trial-geometry-missing-keys", ("executor", "trial", "--part", "p1", "--hole", "r1", "--assembly", "asm"),
     assembly(**{"geometry.toml": "[plate]\ntop_z = 0.1\n"}), 2, "tile_size"),
    ("trial-geometry-rect-short-side-first", ("executor", "trial", "--part", "p3", "--hole", "s1", "--assembly", "asm"),
     assembly(**{"geometry.toml": (CRANFIELD / "geometry.toml").read_text().replace(
         'kind = "square"\nsize = 0.0133', 'kind = "rect"\nsize = [0.010, 0.0133]', 1)}), 2, "a >= b"),
    ("trial-geometry-unknown-kind", ("executor", "trial", "--part", "p1", "--hole", "r1", "--assembly", "asm"),
     assembly(**{"geometry.toml": (CRANFIELD / "geometry.toml").read_text().replace(
         'kind = "round"', 'kind = "oval"', 1)}), 2, "oval"),
    ("trial-part-shape-against-kind", ("executor", "trial", "--part", "p1", "--hole", "r1", "--assembly", "asm"),
     assembly(**{"assembly.toml": (CRANFIELD / "assembly.toml").read_text().replace(
         'role = "peg"', 'role = "peg"\nshape = "square"', 1)}), 2, "kind"),
    ("assembly-part-shape-unknown", ("executor", "trial", "--part", "p1", "--hole", "r1", "--assembly", "asm"),
     assembly(**{"assembly.toml": (CRANFIELD / "assembly.toml").read_text().replace(
         'role = "peg"', 'role = "peg"\nshape = "hex"', 1)}), 2, "shape"),
    ("section-of-unlike-parts", ("executor", "trial", "--part", "rect8", "--hole", "slot8", "--assembly", "asm"),
     taskboard(**{"assembly.toml": (TASKBOARD / "assembly.toml").read_text().replace(
         'shape = "rect"\n', 'shape = "rect"\nsection = "slab"\n')}), 2, "scaled copies"),
    ("assembly-section-without-rect", ("executor", "trial", "--part", "p1", "--hole", "r1", "--assembly", "asm"),
     assembly(**{"assembly.toml": (CRANFIELD / "assembly.toml").read_text().replace(
         'role = "peg"', 'role = "peg"\nshape = "round"\nsection = "a"', 1)}), 2, "section"),
    # learned facts: arity, ids, cycles, contradictions
    ("assign-arity", ("assign", "f.lp"), {"f.lp": "part(a). hole(r1). fits(a,r1,x).\n"}, 2, "fits/2"),
    ("plan-arity", ("plan", "f.lp"), {"f.lp": "part(a;b). must_precede(a,b,c).\n"}, 2, "must_precede/2"),
    ("count-arity", ("precedence", "count", "f.lp"), {"f.lp": "part(a;b). must_precede(a,b,c).\n"}, 2,
     "must_precede/2"),
    ("assign-cycle", ("assign", "f.lp"), {"f.lp": "part(a;b;c). must_precede(a,b). must_precede(b,c). "
                                                  "must_precede(c,a).\n"}, 2, "cycle"),
    ("plan-cycle", ("plan", "f.lp"), {"f.lp": "part(a;b). must_precede(a,b). must_precede(b,a).\n"}, 2, "cycle"),
    ("assign-fits-and-no-fit", ("assign", "f.lp"), {"f.lp": "part(a). hole(r1). fits(a,r1). no_fit(a,r1).\n"}, 2,
     "no_fit(a,r1)"),
    ("plan-fits-and-no-fit", ("plan", "f.lp"), {"f.lp": "part(a). hole(r1). fits(a,r1). no_fit(a,r1).\n"}, 2,
     "no_fit(a,r1)"),
    ("sizes-truth-quoted-id", ("sizes", "learn", "--truth", "t.lp"), {"t.lp": 'part("ä"). hole(r1).\n'}, 2,
     '"ä"'),
    ("assign-quoted-id", ("assign", "t.lp"), {"t.lp": 'part("ä"). hole(r1). fits("ä",r1).\n'}, 2, '"ä"'),
    ("assign-non-ascii", ("assign", "f.lp"), {"f.lp": "part(\u00e4). hole(r1).\n"}, 2, "outside a string"),
    ("learn-png-folder", ("precedence", "learn", "--assembly", "cranfield", "--png", "pictures"),
     lambda tmp: (tmp / "pictures").mkdir(), 2, ".png"),
    # bounds
    ("learn-huge-step", ("precedence", "learn", "d.lp"), {"d.lp": "demo(1,1,bp). demo(1,2147483647,p1)."}, 2,
     "step"),
    ("count-too-many-parts", ("precedence", "count", "f.lp"),
     {"f.lp": " ".join(f"part(p{i})." for i in range(65))}, 2, "at most 64"),
    ("count-huge-file", ("precedence", "count", "f.lp"), {"f.lp": "part(a).\n" + "%" * (11 * 2**20)}, 2,
     "larger than"),
    ("learn-huge-token", ("precedence", "learn", "d.txt"), {"d.txt": "p" * 2**20 + " q\n"}, 2, "…"),
    ("suggest-too-many-demos", ("precedence", "suggest", "d.txt"), {"d.txt": "a b c\n" * 1001}, 2, "1000"),
    # the cell's other commands and every benchmark: argparse errors are one line too
    ("serve-delay-nan", ("executor", "serve", "--delay", "nan"), None, 2, "--delay"),
    ("serve-unknown-option", ("executor", "serve", "--bogus"), None, 2, "unrecognized"),
    ("serve-bad-cell-id", ("executor", "serve", "--cell", "C!"), None, 2, "cell id"),
    ("campaign-trials-zero", ("executor", "campaign", "--trials", "0"), None, 2, "--trials"),
    ("campaign-workers-huge", ("executor", "campaign", "--workers", "1e3"), None, 2, "--workers"),
    ("margins-seed-negative", ("executor", "margins", "--seed", "-1"), None, 2, "--seed"),
    ("margins-trials-missing", ("executor", "margins", "--trials"), None, 2, "--trials"),
    ("bench-unknown", ("bench", "nosuch"), None, 2, "nosuch"),
    ("bench-sizes-list", ("bench", "sizes", "--sizes", "3,y"), None, 2, "--sizes"),
    ("bench-sizes-seeds-zero", ("bench", "sizes", "--noise", "0.1", "--seeds", "0"), None, 2, "--seeds"),
    ("bench-dominance-seconds-nan", ("bench", "dominance", "--seconds", "nan"), None, 2, "--seconds"),
    ("bench-dominance-sizes", ("bench", "dominance", "--sizes", "4y5"), None, 2, "--sizes"),
    ("bench-plan-parts-huge", ("bench", "plan", "--parts", "100"), None, 2, "--parts"),
    ("bench-precedence-repeat-zero", ("bench", "precedence", "--repeat", "0"), None, 2, "--repeat"),
    ("bench-session-product-one", ("bench", "session", "--product", "1"), None, 2, "--product"),
    ("bench-session-delay-negative", ("bench", "session", "--delay", "-1"), None, 2, "--delay"),
    ("bench-executor-workers-zero", ("bench", "executor", "--workers", "0"), None, 2, "--workers"),
    ("bench-executor-unknown-option", ("bench", "executor", "--bogus"), None, 2, "unrecognized"),
    # demonstrations that say where a part went (part@hole)
    ("learn-unknown-hole", ("precedence", "learn", "d.txt", "--assembly", "cranfield"),
     {"d.txt": "bp p2@r2 p1@q9 p3 p4 sp sh ph pd fp\n"}, 2, "d.txt:1: 'p1@q9': unknown hole"),
    ("learn-hole-not-an-id", ("precedence", "learn", "d.txt"), {"d.txt": "a b@B c\n"}, 2, "d.txt:1: 'b@B'"),
    ("learn-hole-twice", ("precedence", "learn", "d.txt"), {"d.txt": "a@x b@x c\n"}, 2, "already holds a"),
    ("sizes-demos-base-plate-in-a-hole", ("sizes", "learn", "--assembly", "cranfield", "--demos", "d.txt"),
     {"d.txt": "bp@r1 p2 p1 p3 p4 sp sh ph pd fp\n"}, 2, "bp@r1"),
    ("session-demos-unknown-hole", ("session", "--demos", "d.txt"),
     {"d.txt": "bp p2@r9 p1 p3 p4 sp sh ph pd fp\n"}, 2, "d.txt:1: 'p2@r9'"),
    ("bench-sizes-demos-unknown-hole", ("bench", "sizes", "--demos", "d.txt", "--seeds", "1"),
     {"d.txt": "bp p2@r9 p1 p3 p4 sp sh ph pd fp\n"}, 2, "d.txt:1: 'p2@r9'"),
    ("resume-demos-not-a-path", ("session", "--resume", "run"),
     {"run/session.json": '{"assembly": "cranfield", "policy": "best", "seed": 0, "recording_id": "r", "demos": 7}'},
     2, '"demos"'),
    # a closed pipe: quiet, exit 141 like `yes | head -1`
    ("enumerate-head", ("precedence", "enumerate", "--assembly", "cranfield"), None, EXIT_BROKEN_PIPE, ""),
    ("sample-head", ("precedence", "sample", "--assembly", "cranfield", "-n", "20000"), None, EXIT_BROKEN_PIPE, ""),
]


def _module(argv: tuple[str, ...]) -> tuple[str, tuple[str, ...]]:
    """The module run.sh runs for ``argv``, and its arguments."""
    if argv[0] == "executor":
        return "executor", argv[1:]
    if argv[:2] == ("bench", "executor"):
        return "executor.campaign.bench", argv[2:]
    return "asp.cli", argv


def _run(argv: tuple[str, ...], tmp: Path, head: bool) -> tuple[int, str]:
    module, args = _module(argv)
    process = subprocess.Popen(python_argv(module, *args), cwd=tmp, env=child_env(), stdin=subprocess.DEVNULL,
                               stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        if head:
            assert process.stdout is not None
            process.stdout.readline()
            process.stdout.close()
            code = process.wait(timeout=60)
            assert process.stderr is not None
            return code, process.stderr.read()
        _out, err = process.communicate(timeout=60)
        return process.returncode, err
    finally:
        if process.poll() is None:
            process.kill()
            process.wait()


@pytest.mark.slow  # one process per case: about 0.5 s each
@pytest.mark.parametrize(("argv", "setup", "code", "word"), [case[1:] for case in CASES],
                         ids=[case[0] for case in CASES])
def test_bad_input_gives_one_line_error(argv: tuple[str, ...], setup: Setup, code: int, word: str,
                                        tmp_path: Path) -> None:
    (tmp_path / "facts.lp").write_text("part(p1). hole(r1). fits(p1,r1).\n")
    if callable(setup):
        setup(tmp_path)
    elif setup:
        for name, content in setup.items():
            path = tmp_path / name
            path.parent.mkdir(parents=True, exist_ok=True)
            path.write_bytes(content if isinstance(content, bytes) else content.encode())
    returncode, stderr = _run(argv, tmp_path, head=code == EXIT_BROKEN_PIPE)
    lines = [line for line in stderr.splitlines() if line.strip() and not line.startswith("pybullet build time")]
    assert "Traceback" not in stderr, stderr[-3000:]
    assert returncode == code, stderr[-3000:]
    if code == EXIT_BROKEN_PIPE:
        assert lines == [], stderr[-3000:]
        return
    assert len(lines) == 1 and lines[0].startswith("error: "), stderr[-3000:]
    assert word in lines[0]
    assert len(lines[0]) < 600, "an error message must not echo long input"
