"""A corpus of bad input for both command lines (repository level: it spans the packages).

One row per case: ``(id, argv, setup, expected exit code, a word the message must hold)``.
``argv`` runs the one command line, ``assembly_constraints.cli.main(argv)``, in this process
in ``tmp_path`` (the fixture ``run_main``); the rows of :data:`PROCESS_ROWS`, one per kind of
command, also run as ``python -m assembly_constraints`` (as ``./run.sh`` does), a process of
their own. ``setup`` is None, a dict of input files (name → text or bytes) or a callable
``setup(tmp_path)``. Every bad input must give one line ``error: ...`` on stderr holding the
word, the exit code, and never a traceback.

Rows expecting :data:`EXIT_BROKEN_PIPE` run as processes only, as ``... | head -1``: stdout
is closed after its first line, and stderr must stay empty.

Unreadable files: ``chmod 000`` does not stop root (the tests may run as root), so under
root the file is replaced by a symbolic link to ``/proc/self/mem``, a regular file whose
read fails with an I/O error for every user (checked; the case is skipped otherwise).
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
import threading
from collections.abc import Callable
from pathlib import Path

import pytest

from asp.session.journal import MAX_JOURNAL_BYTES
from bridge.assembly import load_assembly
from bridge.errors import EXIT_BROKEN_PIPE
from tests.conftest import CLI_MODULE, ROOT, child_env, error_lines, python_argv

CRANFIELD = ROOT / "data" / "cranfield"
TRUTH = (str(CRANFIELD / "sizes.lp"), str(CRANFIELD / "precedence.lp"))
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


def geometry(old: str, new: str) -> Callable[[Path], None]:
    """Setup: the Cranfield copy of :func:`assembly` with ``old`` replaced by ``new`` in
    its ``geometry.toml``."""
    return assembly(**{"geometry.toml": (CRANFIELD / "geometry.toml").read_text().replace(old, new, 1)})


def taught(path: str, old: str, new: str) -> Callable[[Path], None]:
    """Setup: a copy of the spare-hole plate in ``asm/`` with its skills, ``old`` replaced
    by ``new`` in its file ``path`` (a product changed since its skills were taught)."""

    def setup(tmp: Path) -> None:
        shutil.copytree(ROOT / "data" / "spare", tmp / "asm", ignore=shutil.ignore_patterns("assets"))
        edited = tmp / "asm" / path
        text = edited.read_text()
        assert old in text
        edited.write_text(text.replace(old, new, 1))

    return setup


def prior(*margins: str) -> dict[str, str | bytes]:
    """Setup: a product ``pr`` of two round pegs (u, v) and three holes (k1 k2 k3), its CAD
    prior ``nominal_sizes.lp`` holding six consistent margins and then ``margins``."""
    return {"pr/assembly.toml": "name = 'pr'\n[parts.u]\nshape = 'round'\n[parts.v]\nshape = 'round'\n"
                                "[holes.k1]\n[holes.k2]\n[holes.k3]\n",
            "pr/sizes.lp": "part(u;v). hole(k1;k2;k3). fits(u,k1). fits(u,k2). fits(u,k3). fits(v,k3).\n",
            "pr/nominal_sizes.lp": "\n".join(["nominal_margin(u,k1,800).", "nominal_margin(u,k2,400).",
                                               "nominal_margin(u,k3,1200).", "nominal_margin(v,k1,-400).",
                                               "nominal_margin(v,k2,-20).", "nominal_margin(v,k3,300).",
                                               *margins]) + "\n"}


PRIOR = ("sizes", "learn", "--assembly", "pr", "--prior", "cad", "--tolerance", "0.0001")


def plan_file(name: str, change: Callable[[list[dict]], object]) -> Callable[[Path], None]:
    """Setup: ``name`` holding Cranfield's first plan (real clingo, true facts) as ``plan
    --json`` prints it, after ``change`` edited its list of steps in place."""

    def setup(tmp: Path) -> None:
        from asp.assemble.cli import truth_facts
        from asp.plans.plans import plans

        steps = plans(truth_facts(load_assembly("cranfield")))[0].as_json()
        change(steps)
        (tmp / name).write_text(json.dumps({"plans": [steps]}))

    return setup


def _hole_of(part: str, hole: str | None) -> Callable[[list[dict]], object]:
    return lambda steps: [step.update(hole=hole) for step in steps if step["part"] == part]


def _part(old: str, new: str) -> Callable[[list[dict]], object]:
    return lambda steps: [step.update(part=new) for step in steps if step["part"] == old]


def ilc_state(value: object = 0.0, iterations: object = 1) -> str:
    """An ILC state file of ``executor serve --ilc-state`` (50 bins) whose corrections all
    hold ``value`` (JSON text, e.g. ``NaN``) and whose key was taught ``iterations`` times."""
    rows = ", ".join([f"[{value}, 0, 0, 0, 0]"] * 50)
    return f'{{"keys": {{"round_peg:r1": {{"iterations": {iterations}, "correction": [{rows}]}}}}}}'


SETTINGS = '{"assembly": "cranfield", "policy": "best", "seed": 0, "recording_id": "r"}'
JOURNAL_LINE = '{{"id":"{id}","part":"{part}","hole":"{hole}","result":"{result}","cell":"c1"{extra}}}\n'


def resume(*lines: str, settings: str = SETTINGS) -> dict[str, str | bytes]:
    """Setup: a run folder ``run`` to resume with these journal lines."""
    return {"run/session.json": settings, "run/journal.jsonl": "".join(lines)}


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
    # a session's cells answer from the product's geometry: without one, refused before any cell starts
    ("session-sim-no-geometry", ("session", "--assembly", "asm", "--out", "run"),
     assembly(**{"geometry.toml": lambda tmp: (tmp / "asm" / "geometry.toml").unlink()}), 2,
     "asm/geometry.toml: no such file; the cells a session starts (--backend sim) answer from"),
    ("session-truth-no-geometry-no-sizes", ("session", "--backend", "truth", "--assembly", "asm", "--out", "run"),
     assembly(**{"geometry.toml": lambda tmp: (tmp / "asm" / "geometry.toml").unlink(),
                 "sizes.lp": lambda tmp: (tmp / "asm" / "sizes.lp").unlink()}), 2,
     "asm/geometry.toml: no such file; the cells a session starts (--backend truth) answer from geometry.toml or"),
    # session --resume with a damaged session.json: fails before any cell starts
    ("resume-empty", ("session", "--resume", "run"), {"run/session.json": ""}, 2, "JSON"),
    ("resume-binary", ("session", "--resume", "run"), {"run/session.json": b"\x00\xff\xfe{"}, 2, "JSON"),
    ("resume-list", ("session", "--resume", "run"), {"run/session.json": "[1, 2]"}, 2, "object"),
    ("resume-missing-keys", ("session", "--resume", "run"), {"run/session.json": "{}"}, 2, '"assembly": missing'),
    ("resume-wrong-types", ("session", "--resume", "run"),
     {"run/session.json": '{"assembly": "cranfield", "policy": "best", "seed": "x", "recording_id": "r"}'}, 2,
     '"seed"'),
    ("resume-bad-policy", ("session", "--resume", "run"),
     {"run/session.json": '{"assembly": "cranfield", "policy": 7, "seed": 0, "recording_id": "r"}'}, 2,
     '"policy"'),
    ("resume-bad-cell-options", ("session", "--resume", "run"),
     {"run/session.json": '{"assembly": "cranfield", "policy": "best", "seed": 0, "recording_id": "r", '
                          '"cell_options": ["--layer", "sideways"]}'}, 2,
     '"cell_options" (format 1, read as "cell"): "cell.layer"'),
    ("resume-huge-journal", ("session", "--resume", "run"),
     lambda tmp: huge_journal(tmp / "run"), 2, "larger than"),
    # recordings, cell geometry
    ("view-garbage", ("view", "g.rrd", "--print"), {"g.rrd": bytes(range(256)) * 8}, 2, "Rerun recording"),
    ("view-empty", ("view", "e.rrd", "--print"), {"e.rrd": b""}, 2, "Rerun recording"),
    ("trial-binary-geometry", ("executor", "trial", "--part", "p1", "--hole", "r1", "--assembly", "asm"),
     assembly(**{"geometry.toml": bytes(range(256))}), 2, "geometry.toml"),
    ("trial-geometry-missing-keys", ("executor", "trial", "--part", "p1", "--hole", "r1", "--assembly", "asm"),
     assembly(**{"geometry.toml": "[plate]\ntop_z = 0.1\n"}), 2, "tile_size"),
    ("trial-polygon-sides-huge", ("executor", "trial", "--part", "p1", "--hole", "r1", "--assembly", "asm"),
     geometry("polygon_sides = 24", "polygon_sides = 8000000"), 2,
     "[plate] polygon_sides: expected an integer multiple of 8 in 8 .. 256, got 8000000"),
    ("trial-size-string", ("executor", "trial", "--part", "p1", "--hole", "r1", "--assembly", "asm"),
     geometry("size = 0.0120           # diameter [m]", 'size = "12"'), 2, "[part_shapes.round_peg] size"),
    ("trial-peg-half-a-metre", ("executor", "trial", "--part", "p1", "--hole", "r1", "--assembly", "asm"),
     geometry("size = 0.0187", "size = 0.5"), 2, "[part_shapes.shaft] size: expected a number in (0, 0.1] m"),
    ("trial-kind-unknown", ("executor", "trial", "--part", "p1", "--hole", "r1", "--assembly", "asm"),
     geometry('kind = "square"', 'kind = "hexagon"'), 2, "kind: expected one of polygon, rect, round, square"),
    ("teach-demo-hole-unknown", ("executor", "teach", "--assembly", "asm"),
     geometry('demo_hole = "br"', 'demo_hole = "zz"'), 2, "[part_shapes.shaft] demo_hole"),
    ("trial-geometry-rect-short-side-first", ("executor", "trial", "--part", "p3", "--hole", "s1", "--assembly", "asm"),
     assembly(**{"geometry.toml": (CRANFIELD / "geometry.toml").read_text().replace(
         'kind = "square"\nsize = 0.0133', 'kind = "rect"\nsize = [0.010, 0.0133]', 1)}), 2, "a >= b"),
    ("trial-geometry-unknown-kind", ("executor", "trial", "--part", "p1", "--hole", "r1", "--assembly", "asm"),
     assembly(**{"geometry.toml": (CRANFIELD / "geometry.toml").read_text().replace(
         'kind = "round"', 'kind = "oval"', 1)}), 2, "oval"),
    ("trial-part-shape-against-kind", ("executor", "trial", "--part", "p1", "--hole", "r1", "--assembly", "asm"),
     assembly(**{"assembly.toml": (CRANFIELD / "assembly.toml").read_text().replace(
         'role = "peg"\nshape = "round"', 'role = "peg"\nshape = "square"', 1)}), 2, "kind"),
    ("assembly-part-shape-unknown", ("executor", "trial", "--part", "p1", "--hole", "r1", "--assembly", "asm"),
     assembly(**{"assembly.toml": (CRANFIELD / "assembly.toml").read_text().replace(
         'role = "peg"\nshape = "round"', 'role = "peg"\nshape = "hex"', 1)}), 2, "shape: expected one of"),
    ("section-of-unlike-parts", ("executor", "trial", "--part", "rect8", "--hole", "slot8", "--assembly", "asm"),
     taskboard(**{"assembly.toml": (TASKBOARD / "assembly.toml").read_text().replace(
         'role = "peg"\nshape = "rect"\n', 'role = "peg"\nshape = "rect"\nsection = "slab"\n')}), 2, "scaled copies"),
    ("assembly-section-without-rect", ("executor", "trial", "--part", "p1", "--hole", "r1", "--assembly", "asm"),
     assembly(**{"assembly.toml": (CRANFIELD / "assembly.toml").read_text().replace(
         'role = "peg"\nshape = "round"', 'role = "peg"\nshape = "round"\nsection = "a"', 1)}), 2,
     "section: only a part of shape"),
    # the product tables and the cell description (bridge/product, executor/cell_description.py)
    ("trial-cover-mass-zero", ("executor", "trial", "--part", "p1", "--hole", "r1", "--assembly", "asm"),
     geometry("mass = 0.05             # [kg]\ngrip", "mass = 0             # [kg]\ngrip"), 2,
     "[covers.sp] mass: expected a number in (0, 10] kg, got 0"),
    ("trial-head-kind-unknown", ("executor", "trial", "--part", "p1", "--hole", "r1", "--assembly", "asm"),
     geometry('into = "pd"\nkind = "round"', 'into = "pd"\nkind = "rect"'), 2,
     "[heads.ph] kind: expected one of round, square, got 'rect'"),
    ("trial-head-into-unknown", ("executor", "trial", "--part", "p1", "--hole", "r1", "--assembly", "asm"),
     geometry('into = "pd"', 'into = "fp"'), 2, "[heads.ph] into: expected a cover with a socket (pd)"),
    ("trial-base-mass-negative", ("executor", "trial", "--part", "p1", "--hole", "r1", "--assembly", "asm"),
     geometry("mass = 2.0 ", "mass = -2.0 "), 2, "[base] mass: expected a number in (0, 50] kg, got -2.0"),
    ("trial-unknown-key", ("executor", "trial", "--part", "p1", "--hole", "r1", "--assembly", "asm"),
     geometry("[plate]\n", "[plate]\ncolour = 3\n"), 2, "[plate] colour: unknown key; expected one of top_z"),
    ("trial-cover-over-unknown-hole", ("executor", "trial", "--part", "p1", "--hole", "r1", "--assembly", "asm"),
     geometry('over = ["s1", "s2"]', 'over = ["s1", "zz"]'), 2, "[covers.sp] over: expected holes of"),
    ("trial-cover-skill-unknown", ("executor", "trial", "--part", "p1", "--hole", "r1", "--assembly", "asm"),
     geometry('skill = "square_peg"', 'skill = "zz"'), 2, "[covers.sp] skill: expected a part shape"),
    ("plan-bad-product", ("plan", "--optimal", "--assembly", "asm", "asm/sizes.lp", "asm/precedence.lp"),
     geometry('skill = "square_peg"', 'skill = 3'), 2, "[covers.sp] skill: expected an id"),
    ("session-bad-product", ("session", "--assembly", "asm"),
     geometry("[base]\npart = \"bp\"", "[base]\npart = \"zz\""), 2, "[base] part: expected a part of"),
    ("trial-cell-description-unknown-key", ("executor", "trial", "--part", "p1", "--hole", "r1",
                                            "--cell-description", "cell.toml"),
     {"cell.toml": "[thresholds]\nf_top = 3\n"}, 2, "cell.toml: [thresholds] f_top: unknown key"),
    ("trial-cell-description-negative", ("executor", "trial", "--part", "p1", "--hole", "r1",
                                          "--cell-description", "cell.toml"),
     {"cell.toml": "[gains]\nk_trans = -1.0\n"}, 2, "cell.toml: [gains] k_trans: expected a number in (0, 1e6]"),
    ("serve-cell-description-missing", ("executor", "serve", "--cell-description", "none.toml"), None, 2,
     "none.toml"),
    ("trial-cell-gripper-too-deep", ("executor", "trial", "--part", "p1", "--hole", "r1",
                                     "--cell-description", "cell.toml"),
     {"cell.toml": "[gripper]\nflange_mass = 1.0\nflange_inertia = 0.004\nflange_length = 0.06\n"
                   "grasp_depth = 0.06\n"}, 2, "length: expected longer than [gripper] grasp_depth (0.06 m)"),
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
    # output paths that are special files: written through or refused, never replaced
    ("learn-out-full-disk", ("precedence", "learn", "--assembly", "cranfield", "--out", "full"),
     lambda tmp: (tmp / "full").symlink_to("/dev/full"), 2, "full: cannot write (No space left on device)"),
    ("learn-out-fifo-no-reader", ("precedence", "learn", "--assembly", "cranfield", "--out", "pipe"),
     lambda tmp: os.mkfifo(tmp / "pipe"), 2, "pipe: cannot write (a FIFO with no reader)"),
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
    # executor serve --settings: one document, checked field by field
    ("serve-settings-not-json", ("executor", "serve", "--settings", "{nope"), None, 2, "--settings: not JSON"),
    ("serve-settings-bad-layer", ("executor", "serve", "--settings", '{"cell": {"layer": "sideways"}}'), None, 2,
     '--settings: "cell.layer": invalid enum value'),
    ("serve-settings-unknown-field", ("executor", "serve", "--settings", '{"cel": {}}'), None, 2,
     "unknown field `cel`"),
    ("serve-settings-and-options", ("executor", "serve", "--settings", "{}", "--cell", "c2"), None, 2,
     "either as one document or as options, not both"),
    ("serve-settings-file-missing", ("executor", "serve", "--settings", "none.json"), None, 2, "none.json"),
    ("serve-settings-file-delay", ("executor", "serve", "--settings", "s.json"), {"s.json": '{"delay_s": -1}'}, 2,
     's.json: "delay_s": expected `float` >= 0.0'),
    ("serve-settings-friction-range", ("executor", "serve", "--settings",
                                       '{"cell": {"magnitudes": {"friction_min": 0.9}}}'), None, 2,
     "friction_min 0.9 > friction_max 0.5"),
    ("serve-settings-cell-description", ("executor", "serve", "--settings", '{"cell": {"description": "d.toml"}}'),
     None, 2, "d.toml: no such cell description"),
    ("session-friction-range", ("session", "--friction-min", "0.9"), None, 2, "friction_min 0.9 > friction_max 0.5"),
    ("resume-format-3", ("session", "--resume", "run"),
     {"run/session.json": '{"format": 3, "assembly": "cranfield", "policy": "best", "seed": 0, "recording_id": "r"}'},
     2, "format 3: expected 2"),
    ("campaign-trials-zero", ("executor", "campaign", "--trials", "0"), None, 2, "--trials"),
    ("campaign-jobs-huge", ("executor", "campaign", "--jobs", "1e3"), None, 2, "--jobs"),
    ("margins-seed-negative", ("executor", "margins", "--seed", "-1"), None, 2, "--seed"),
    ("margins-trials-missing", ("executor", "margins", "--trials"), None, 2, "--trials"),
    ("bench-unknown", ("bench", "nosuch"), None, 2, "nosuch"),
    ("bench-sizes-list", ("bench", "sizes", "--sizes", "3,y"), None, 2, "--sizes"),
    ("bench-sizes-seeds-zero", ("bench", "sizes", "--noise", "0.1", "--seeds", "0"), None, 2, "--seeds"),
    ("bench-dominance-time-limit-nan", ("bench", "dominance", "--time-limit", "nan"), None, 2, "--time-limit"),
    ("bench-dominance-sizes", ("bench", "dominance", "--sizes", "4y5"), None, 2, "--sizes"),
    ("bench-plan-parts-huge", ("bench", "plan", "--parts", "100"), None, 2, "--parts"),
    ("bench-precedence-repeat-zero", ("bench", "precedence", "--repeat", "0"), None, 2, "--repeat"),
    ("bench-session-product-one", ("bench", "session", "--product", "1"), None, 2, "--product"),
    ("bench-session-delay-negative", ("bench", "session", "--delay", "-1"), None, 2, "--delay"),
    ("bench-executor-jobs-zero", ("bench", "executor", "--jobs", "0"), None, 2, "--jobs"),
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
    # plans and facts against the product: ids reach clingo as symbols, never as program text
    ("assemble-plan-injected-fact", ("assemble", "p.json", "--backend", "truth"),
     plan_file("p.json", _hole_of("p1", "r3). hole(zz). fits(p1,zz")), 2, "p.json: plans[1]: step 9: hole"),
    ("assemble-plan-injected-interval", ("assemble", "p.json", "--backend", "truth"),
     plan_file("p.json", _hole_of("p1", "r3). bomb(1..50000000")), 2, "p.json: plans[1]: step 9: hole"),
    ("assemble-plan-keyword-id", ("assemble", "p.json", "--backend", "truth"),
     plan_file("p.json", _hole_of("p1", "not")), 2, "step 9: hole \"not\" is not an id"),
    ("assemble-plan-non-ascii-id", ("assemble", "p.json", "--backend", "truth"),
     plan_file("p.json", _part("p1", "p\u00e91")), 2, "step 9: part"),
    ("assemble-plan-surrogate-id", ("assemble", "p.json", "--backend", "truth"),
     {"p.json": '[{"part": "bp", "hole": null}, {"part": "p\\ud800", "hole": "r1"}]'}, 2, "step 2: part"),
    ("assemble-plan-trailing-newline-id", ("assemble", "p.json", "--backend", "truth"),
     plan_file("p.json", _part("bp", "bp\n")), 2, "step 1: part"),
    ("assemble-plan-unknown-key", ("assemble", "p.json", "--backend", "truth"),
     {"p.json": '[{"part": "bp", "hole": null, "holes": "r1"}]'}, 2, "p.json: step 1: expected"),
    ("assemble-plan-key-twice", ("assemble", "p.json", "--backend", "truth"),
     {"p.json": '[{"part": "bp", "hole": null, "hole": "r1"}]'}, 2, "p.json: the key 'hole' appears twice"),
    ("assemble-plan-deep-nesting", ("assemble", "p.json", "--backend", "truth"),
     {"p.json": "[" * 100_000 + "]" * 100_000}, 2, "nested too deeply"),
    ("assemble-plan-k-of-one", ("assemble", "p.json", "--plan", "5", "--backend", "truth"),
     plan_file("p.json", lambda steps: None), 2, "--plan 5, but the file holds 1 plan(s)"),
    ("assemble-plan-subset", ("assemble", "p.json", "--backend", "truth"),
     plan_file("p.json", lambda steps: steps.__delitem__(slice(2, None))), 2, "p.json: the plan: missing("),
    ("assemble-plan-unknown-part", ("assemble", "p.json", "--backend", "truth"),
     plan_file("p.json", lambda steps: steps.append({"part": "zz", "hole": None})), 2,
     "step 11 (zz): unknown_part(zz)"),
    ("assemble-plan-none-part", ("assemble", "p.json", "--backend", "truth"),
     plan_file("p.json", lambda steps: steps.insert(0, {"part": "none", "hole": None})), 2,
     "step 1 (none): unknown_part(none)"),
    ("assemble-plan-peg-without-hole", ("assemble", "p.json", "--backend", "truth"),
     plan_file("p.json", _hole_of("p1", None)), 2, "step 9 (p1): no_hole(p1)"),
    ("assemble-facts-subset", ("assemble", "f.lp", "--backend", "truth"),
     {"f.lp": "part(bp;p1). hole(r1). fits(p1,r1).\n"}, 2, "f.lp: the facts are not of the product"),
    ("assemble-facts-peg-unknown-sizes", ("assemble", "f.lp", "--backend", "truth"),
     {"f.lp": "part(bp;p1;p2;p3;p4;sh;sp;pd;ph;fp). hole(r1;r2;s1;s2;br). fits(p1,r1). fits(p2,r2). "
              "fits(p3,s1). fits(p4,s2).\n"}, 2, "peg sh of"),
    ("assemble-facts-of-another-assembly", ("assemble", *(str(ROOT / "data" / "graded" / name)
                                                           for name in ("sizes.lp", "precedence.lp")),
                                            "--backend", "truth"), None, 2, "not of the product"),
    ("assemble-uncertainty-cell-truth", ("assemble", "--backend", "truth", "--uncertainty", "cell"), None, 2,
     "--uncertainty cell has no effect with --backend truth"),
    ("assemble-layer-truth", ("assemble", "--backend", "truth", "--layer", "position"), None, 2,
     "--layer has no effect with --backend truth"),
    ("assemble-block-hole-franka", ("assemble", "--backend", "franka", "--backend-option", "host=10.0.0.2",
                                    "--block-hole", "r1"), None, 2, "--block-hole has no effect with --backend franka"),
    ("bench-assemble-uncertainty-cell-truth", ("bench", "assemble", "--backend", "truth", "--plans", "1",
                                               "--uncertainty", "cell", "--grasp-tilt-bias", "2"), None, 2,
     "--uncertainty cell has no effect with --backend truth"),
    ("bench-assemble-magnitude-truth", ("bench", "assemble", "--backend", "truth", "--plans", "1",
                                        "--vision-bias", "0.002"), None, 2,
     "--vision-bias has no effect with --backend truth"),
    ("bench-assemble-facts-subset", ("bench", "assemble", "f.lp", "--backend", "truth", "--plans", "1"),
     {"f.lp": "part(bp;p1). hole(r1). fits(p1,r1).\n"}, 2, "f.lp: the facts are not of the product"),
    ("assemble-run-plan-wrong-types", ("assemble", "--run", "run", "--backend", "truth"),
     {"run/session.json": '{"assembly": "cranfield", "plans": [[{"part": 7, "hole": [1]}]]}',
      "run/learned.lp": "part(bp).\n"}, 2, 'session.json: "plans[0][0][...]": expected `str | null`, got `int`'),
    ("plan-precedence-edge-unknown-part", ("plan", "f.lp"), {"f.lp": "part(a;b). precedence_edge(a,zz).\n"}, 2,
     "precedence_edge(a,zz): zz is not a part/1"),
    ("assembly-keyword-id", ("plan", "facts.lp", "--optimal", "--assembly", "asm"),
     assembly(**{"assembly.toml": "[parts.not]\nname = 'x'\n"}), 2, "[parts.not]"),
    ("assemble-run-assembly-wrong-type", ("assemble", "--run", "run", "--backend", "truth"),
     {"run/session.json": '{"assembly": 7, "plans": []}'}, 2, '"assembly": expected `str`, got `int`'),
    ("bench-assemble-run-assembly-wrong-type", ("bench", "assemble", "--run", "run", "--backend", "truth"),
     {"run/session.json": '{"assembly": ["x"], "plans": []}'}, 2, '"assembly": expected `str`'),
    ("assemble-run-plans-wrong-type", ("assemble", "--run", "run", "--backend", "truth"),
     {"run/session.json": '{"assembly": "cranfield", "plans": {"a": 1}}'}, 2, '"plans": expected `array`'),
    # a journal that contradicts itself, or names what the assembly does not have
    ("resume-journal-contradiction", ("session", "--resume", "run"),
     resume(JOURNAL_LINE.format(id="a", part="p1", hole="br", result="fit", extra=""),
            JOURNAL_LINE.format(id="b", part="p1", hole="br", result="no_fit", extra="")), 2,
     "journal.jsonl:2: p1,br no_fit after fit on line 1, without the retest marker"),
    ("resume-journal-duplicated-line", ("session", "--resume", "run"),
     resume(*[JOURNAL_LINE.format(id="a", part="p1", hole="br", result="fit", extra="")] * 2), 2,
     "journal.jsonl:2: a second result of request a"),
    ("resume-journal-negative-experiment", ("session", "--resume", "run"),
     resume(JOURNAL_LINE.format(id="a", part="p1", hole="br", result="fit", extra=',"experiment":-3')), 2,
     "journal.jsonl:1"),
    ("resume-journal-unknown-part", ("session", "--resume", "run"),
     resume(JOURNAL_LINE.format(id="a", part="p1", hole="br", result="fit", extra=""),
            JOURNAL_LINE.format(id="b", part="zz", hole="br", result="fit", extra="")), 2,
     "journal.jsonl:2: (zz,br): expected a part of"),
    ("resume-recording-id-long", ("session", "--resume", "run"),
     resume(settings=SETTINGS.replace('"r"', '"' + "r" * 200 + '"')), 2, '"recording_id": expected `str` matching'),
    ("resume-starts-at-bound", ("session", "--resume", "run"),
     resume(settings=SETTINGS.replace("}", ', "starts": 1000000}')), 2, '"starts": expected `int` <='),
    ("export-out-empty", ("executor", "export", ""), None, 2, "OUT: expected a path, got the empty string"),
    # the sim cell's ILC state: refused when the cell starts, never at its first insertion
    ("serve-ilc-state-nan", ("executor", "serve", "--ilc-state", "s.json"), {"s.json": ilc_state("NaN")}, 2,
     's.json: "keys" "round_peg:r1" correction[0][0]: expected a number within ±0.002 m, got NaN'),
    ("serve-ilc-state-huge", ("executor", "serve", "--ilc-state", "s.json"), {"s.json": ilc_state("1e300")}, 2,
     'correction[0][0]: expected a number within ±0.002 m, got 1e+300'),
    ("serve-ilc-state-string", ("executor", "serve", "--ilc-state", "s.json"), {"s.json": ilc_state('"0"')}, 2,
     "correction[0][0]"),
    ("serve-ilc-state-fractional-iterations", ("executor", "serve", "--ilc-state", "s.json"),
     {"s.json": ilc_state(iterations="1.5")}, 2, '"round_peg:r1" iterations: expected an integer'),
    ("serve-ilc-state-keys-list", ("executor", "serve", "--ilc-state", "s.json"), {"s.json": '{"keys": []}'}, 2,
     's.json: "keys": expected an object'),
    ("serve-ilc-state-deep-nesting", ("executor", "serve", "--ilc-state", "s.json"),
     {"s.json": '{"keys": ' + "[" * 100_000 + "]" * 100_000 + "}"}, 2, "s.json: nested too deeply"),
    # numbers written with ASCII digits only; list items once
    ("sample-seed-fullwidth", ("precedence", "sample", "--assembly", "cranfield", "--seed", "\uff15"), None, 2,
     "--seed"),
    ("sample-n-underscore", ("precedence", "sample", "--assembly", "cranfield", "-n", "1_0"), None, 2, "-n"),
    ("session-seed-fullwidth", ("session", "--seed", "\uff15"), None, 2, "--seed"),
    ("plan-time-limit-underscore", ("plan", "facts.lp", "--time-limit", "1_0"), None, 2, "--time-limit"),
    ("bench-sizes-noise-fullwidth", ("bench", "sizes", "--noise", "0.\uff11"), None, 2, "--noise"),
    ("bench-executor-executions-underscore", ("bench", "executor", "--executions", "1_0"), None, 2,
     "--executions"),
    ("bench-precedence-physics-edge-twice", ("bench", "precedence-physics", "--edges", "bp-p1,bp-p1"), None, 2,
     "'bp-p1' is given twice"),
    ("session-allow-cells-twice", ("session", "--allow-cells", "c1,c1"), None, 2, "given twice"),
    # a closed pipe: quiet, exit 141 like `yes | head -1`
    ("enumerate-head", ("precedence", "enumerate", "--assembly", "cranfield"), None, EXIT_BROKEN_PIPE, ""),
    ("sample-head", ("precedence", "sample", "--assembly", "cranfield", "-n", "20000"), None, EXIT_BROKEN_PIPE, ""),
    # the probes of the newer inputs, new values of the same kinds: a prior that is a program
    # (unbounded grounding), contradicts itself or names what the product lacks; numbers out of
    # range; empty output paths; a FIFO as a recording
    ("prior-interval-of-other-name", PRIOR, prior("k(1..60000000)."), 2, "nominal_sizes.lp:7: k((1..60000000))"),
    ("prior-pool", PRIOR, prior("nominal_margin(v,k2,(-20;650))."), 2, "nominal_sizes.lp:7:"),
    ("prior-contradicts", PRIOR, prior("nominal_margin(v,k2,650)."), 2,
     "nominal_sizes.lp:7: nominal_margin(v,k2,650) contradicts line 5: nominal_margin(v,k2,-20)"),
    ("prior-unknown-hole", PRIOR, prior("nominal_margin(u,k9,100)."), 2, "unknown part or hole k9"),
    ("prior-function-id", PRIOR, prior("nominal_margin(f(u),k1,100)."), 2, "nominal_sizes.lp:7:"),
    ("serve-delay-over-an-hour", ("executor", "serve", "--delay", "3601"), None, 2, "[0, 3600]"),
    ("session-cells-65", ("session", "--cells", "65"), None, 2, "from 0 to 64"),
    ("trial-trials-over", ("executor", "trial", "--part", "p1", "--hole", "r1", "--trials", "100001"), None, 2,
     "from 1 to 100000"),
    ("assemble-save-empty", ("assemble", "--save", ""), None, 2, "expected a path, got the empty string"),
    ("view-fifo-in-run", ("view", "run", "--print"),
     lambda tmp: ((tmp / "run").mkdir(), os.mkfifo(tmp / "run" / "c3.rrd")), 2, "c3.rrd: not a regular file (a FIFO)"),
    # a skill taught on a section the product no longer has: refused before the cell serves
    ("serve-sim-peg-resized", ("executor", "serve", "--assembly", "asm", "--listen", "tcp/127.0.0.1:0"),
     taught("geometry.toml", "size = 0.0120           # diameter [m]", "size = 0.0125"), 2,
     "taught on part p1 round 12.00 x 12.00 mm, the product's p1 is round 12.50 x 12.50 mm"),
    ("trial-hole-resized", ("executor", "trial", "--assembly", "asm", "--part", "p3", "--hole", "r1"),
     taught("geometry.toml", "size = 0.0133           # side [m]", "size = 0.0131"), 2,
     "taught on hole s1 square 13.30 x 13.30 mm, the product's s1 is square 13.10 x 13.10 mm"),
]


PROCESS_ROWS = ("learn-unreadable-text", "sizes-truth-quoted-id", "plan-cycle", "resume-binary",
                "assemble-plan-injected-fact", "view-garbage", "serve-settings-not-json", "trial-kind-unknown",
                "bench-unknown", "enumerate-head", "sample-head")
"""Rows also run as a process of their own (``python -m assembly_constraints``), one per
kind of command (the planner's subcommands, session, assemble, view, the cell's serve and
trial, bench) and the closed pipes: what the process boundary adds (the interpreter's exit
code, nothing it prints on its way out, PyBullet's banner) is checked there."""


def _threads_children_clients() -> tuple[set[int], set[int], set[int]]:
    """This process's Python threads, child processes and connected PyBullet clients (ids):
    what a command run in this process could leave behind for the next row."""
    children = {int(pid) for task in Path("/proc/self/task").iterdir() for pid in _task_children(task)}
    pybullet = sys.modules.get("pybullet")
    clients = {n for n in range(PYBULLET_CLIENTS) if pybullet.isConnected(physicsClientId=n)} if pybullet else set()
    return {thread.ident or 0 for thread in threading.enumerate()}, children, clients


def _task_children(task: Path) -> list[str]:
    """The child process ids one thread started; none when the thread ended since the listing."""
    try:
        return (task / "children").read_text().split()
    except FileNotFoundError:
        return []


PYBULLET_CLIENTS = 1024  # PyBullet's own bound on the clients of one process (MAX_PHYSICS_CLIENTS)


def _run(argv: tuple[str, ...], tmp: Path, head: bool) -> tuple[int, str]:
    process = subprocess.Popen(python_argv(CLI_MODULE, *argv), cwd=tmp, env=child_env(), stdin=subprocess.DEVNULL,
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


def _set_up(setup: Setup, tmp: Path) -> None:
    """The input files of a row in ``tmp`` (and ``facts.lp``, which rows use as a good one)."""
    (tmp / "facts.lp").write_text("part(p1). hole(r1). fits(p1,r1).\n")
    if callable(setup):
        setup(tmp)
    elif setup:
        for name, content in setup.items():
            path = tmp / name
            path.parent.mkdir(parents=True, exist_ok=True)
            path.write_bytes(content if isinstance(content, bytes) else content.encode())


def _check_one_line(code: int, word: str, returncode: int, stderr: str) -> None:
    """A row's outcome: its exit code, and one line ``error: ...`` holding ``word`` (nothing
    after a closed pipe), never a traceback."""
    lines = error_lines(stderr)
    assert "Traceback" not in stderr, stderr[-3000:]
    assert returncode == code, stderr[-3000:]
    if code == EXIT_BROKEN_PIPE:
        assert lines == [], stderr[-3000:]
        return
    assert len(lines) == 1 and lines[0].startswith("error: "), stderr[-3000:]
    assert word in lines[0]
    assert len(lines[0]) < 600, "an error message must not echo long input"


IN_PROCESS = [pytest.param(*case[1:], id=case[0]) for case in CASES if case[3] != EXIT_BROKEN_PIPE]


@pytest.mark.parametrize(("argv", "setup", "code", "word"), IN_PROCESS)
def test_bad_input_gives_one_line_error(argv: tuple[str, ...], setup: Setup, code: int, word: str,
                                        tmp_path: Path, run_main) -> None:
    """Every row but the closed pipes, run in this process (``run_main``: ``main(argv)``, its
    exit code, its stderr; an exception escaping it fails the test as a traceback would): it
    leaves no thread, child process or PyBullet client behind (nor, by ``run_main``, a
    working directory, environment, log handler or signal handler)."""
    _set_up(setup, tmp_path)
    before = _threads_children_clients()
    done = run_main(*argv, cwd=tmp_path)
    _check_one_line(code, word, done.returncode, done.stderr)
    assert _threads_children_clients() == before, "the command left a thread, a process or a PyBullet client"


@pytest.mark.slow  # a process each: about 1.5 s of CPU
@pytest.mark.parametrize(("argv", "setup", "code", "word"),
                         [pytest.param(*case[1:], id=case[0]) for case in CASES if case[0] in PROCESS_ROWS])
def test_bad_input_gives_one_line_error_as_a_process(argv: tuple[str, ...], setup: Setup, code: int, word: str,
                                                     tmp_path: Path) -> None:
    """:data:`PROCESS_ROWS` as processes; rows expecting :data:`EXIT_BROKEN_PIPE` as ``... | head -1``."""
    _set_up(setup, tmp_path)
    _check_one_line(code, word, *_run(argv, tmp_path, head=code == EXIT_BROKEN_PIPE))


def test_every_process_row_is_a_row() -> None:
    assert set(PROCESS_ROWS) <= {case[0] for case in CASES}
