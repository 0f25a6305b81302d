"""The Python API: what the command line does, as typed functions to script against.

>>> from assembly_constraints import api
>>> relation = api.learn_precedence("cranfield")            # Algorithm 1 on the demonstrations
>>> truth = api.truth_oracle("cranfield")                     # or any object with ask(part, hole)
>>> sizes = api.learn_sizes(truth, truth.parts, truth.holes)  # active exploration, policy "best"
>>> facts = api.write_facts("learned.lp", relation, sizes)
>>> first = api.plan([facts], n=1)[0]                         # a complete plan, checked
>>> result = api.run_session("cranfield", api.SessionOptions(backend="truth", out="runs/x"))  # + a cell
>>> run = api.read_run("runs/x")                              # its settings, journal, files

Paths are relative to the working folder; an assembly is a shipped one's name
(``cranfield``, ``battery``, ``spare``, ``graded``) or a folder holding ``assembly.toml``. Bad input raises
:class:`asp.PlannerError` or :class:`bridge.BridgeError`
with a one-line message naming the file or value. Documented in ``docs/api.md``.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Literal, NotRequired, TypedDict

from msgspec import UNSET

from asp import PlannerError
from asp.plans.assign import load_learned_facts
from asp.plans.plans import Plan, check_plan, plans
from asp.precedence.demos import load_demos
from asp.precedence.learn import learn_must_precede
from asp.precedence.relation import Relation, precedence_facts
from asp.session.journal import JOURNAL_NAME, JournalEntry, read_journal
from asp.session.settings import SessionFile, SessionSettings, read_session_file
from asp.sizes.learner import Experiment, LearningOptions, SizeLearningResult
from asp.sizes.learner import learn_sizes as _learn_sizes
from asp.sizes.truth_oracle import Oracle, TruthOracle
from asp.solve import write_facts as _write_facts
from bridge.assembly import load_assembly
from bridge.cell_settings import CellSettings, Magnitudes

Result = Literal["fit", "no_fit"]
"""The outcome of one insertion experiment."""

__all__ = ["CellSettings", "Experiment", "JournalEntry", "Magnitudes", "Plan", "PlannerError", "Relation", "Result",
           "RunFolder", "SessionFile", "SessionOptions", "SessionResult", "SizeLearningResult", "learn_precedence",
           "learn_sizes", "plan", "read_run", "run_session", "truth_oracle", "write_facts"]


def learn_precedence(assembly: str | Path = "cranfield", demos: str | Path | None = None,
                     min_support: int = 1) -> Relation:
    """The must-precede relation learned from demonstrated sequences (paper Algorithm 1).

    ``demos``: a demonstrations file (one sequence of part ids a line, or ``demo/3``
    facts); default the assembly's ``demos.txt``. ``min_support`` K: a constraint is
    dropped only when at least K demonstrations contradict it (1: plain intersection).
    ``Relation.pairs()`` lists the learned (before, after) pairs.
    """
    folder = load_assembly(str(assembly))
    path = Path(demos) if demos is not None else folder.file("demos.txt")
    return learn_must_precede(load_demos(path, parts=folder.part_ids), min_support=min_support)


def truth_oracle(assembly: str | Path = "cranfield") -> TruthOracle:
    """An oracle answering from the assembly's ``sizes.lp`` (which part fits which hole);
    its ``parts`` and ``holes`` are the pairs to learn."""
    return TruthOracle.from_assembly(str(load_assembly(str(assembly)).folder))


class _CallableOracle:
    """An :class:`asp.sizes.truth_oracle.Oracle` around a function ``(part, hole) -> result``."""

    def __init__(self, ask: Callable[[str, str], Result]) -> None:
        self._ask = ask

    def ask(self, part: str, hole: str) -> Result:
        result = self._ask(part, hole)
        if result not in ("fit", "no_fit"):
            raise PlannerError(f"oracle answered {result!r} for ({part},{hole}); expected 'fit' or 'no_fit'")
        return result


def learn_sizes(oracle: Oracle | Callable[[str, str], Result], parts: Sequence[str], holes: Sequence[str],
                policy: str = "best", seed: int = 0, confirm: int = 0,
                on_experiment: Callable[[Experiment], None] | None = None) -> SizeLearningResult:
    """Which part fits which hole, by asking ``oracle`` the experiments ``policy`` chooses.

    ``oracle``: an object with ``ask(part, hole) -> "fit" | "no_fit"`` or such a function
    (a robot, a simulator, :func:`truth_oracle`). ``policy``: ``systematic``, ``random``,
    ``heuristic`` or ``best`` (fewest experiments). ``confirm`` K: re-test each essential
    observation until its result leads by K+1 answers (for a noisy oracle).
    ``on_experiment`` is called after each experiment. The result's ``knowledge.fits``
    holds the fitting pairs, ``experiments`` the experiments in order.
    """
    asker = oracle if hasattr(oracle, "ask") else _CallableOracle(oracle)
    report = None if on_experiment is None else (lambda experiment, _knowledge: on_experiment(experiment))
    return _learn_sizes(parts, holes, asker, policy, seed, on_experiment=report,
                        options=LearningOptions(confirm=confirm))


def write_facts(path: str | Path, precedence: Relation | None = None,
                sizes: SizeLearningResult | None = None) -> Path:
    """Write learned facts for the planner (and plain clingo): ``part/1``,
    ``must_precede/2``, ``precedence_edge/2`` of ``precedence``; ``hole/1``, ``tried/4``,
    ``fits/2``, ``no_fit/2`` of ``sizes``. Written atomically; returns the path."""
    atoms = (precedence_facts(precedence) if precedence is not None else []) + (sizes.facts() if sizes else [])
    _write_facts(Path(path), list(dict.fromkeys(atoms)), header="Learned facts (assembly_constraints.api).")
    return Path(path)


def plan(facts: Sequence[str | Path], n: int = 1) -> list[Plan]:
    """Up to ``n`` complete plans (0: all) from learned facts files: a hole for every part
    that needs one and an order respecting ``must_precede``; each checked by the
    independent plan checker. :class:`asp.plans.assign.UnsolvableAssembly` names a part
    without a hole."""
    learned = load_learned_facts([Path(f) for f in facts])
    found = plans(learned, n=n)
    for candidate in found:
        errors = check_plan(learned, candidate.steps)
        if errors:
            raise PlannerError(f"plan {candidate.as_json()} fails the checker: {errors}")
    return found


class SessionResult(TypedDict):
    """What a session returns (the ``session --json`` contract); ``error`` (with ``plans``
    empty) when the learned relation has no complete hole assignment."""

    run: str
    experiments: int
    fits: list[list[str]]
    must_precede: list[list[str]]
    plans: list[list[dict[str, str | None]]]
    matches_truth: bool | None
    error: NotRequired[str]


@dataclass(frozen=True)
class SessionOptions:
    """How :func:`run_session` runs (the options of ``assembly-constraints session``):
    ``out`` the run folder (default ``runs/<UTC time>``); ``backend`` ``sim`` (PyBullet) or
    ``truth`` (answers from the geometry, fast); ``cells`` cell processes to start, or 0 to
    use the cells reachable at the Zenoh endpoints ``connect``; the size ``policy``, its
    ``seed`` and ``confirm`` (re-tests per outcome); ``timeout_s`` [s]: one experiment at
    one cell before it is sent again; ``plans`` to compute; ``cell``: the simulated cells'
    execution layer and uncertainty (default: the defaults, cell seed ``seed``), cell
    ``c<k>`` having cell seed ``cell.cell_seed + k - 1``."""

    out: str | Path | None = None
    backend: Literal["sim", "truth"] = "sim"
    cells: int = 1
    policy: str = "best"
    seed: int = 0
    confirm: int = 0
    timeout_s: float = 120.0
    plans: int = 5
    connect: Sequence[str] = ()
    cell: CellSettings | None = None


def run_session(assembly: str | Path = "cranfield", options: SessionOptions | None = None) -> SessionResult:
    """A whole learning session (``assembly-constraints session``) on ``assembly`` as
    ``options`` say (default: :class:`SessionOptions`' defaults): learns precedence from
    the demonstrations, starts the cells or uses those reachable, learns the sizes, plans,
    and writes the run folder. PlannerError naming the setting when one is out of range."""
    from asp.session.run import run_session as run

    chosen = SessionOptions() if options is None else options
    settings = SessionSettings(assembly=str(assembly), out=None if chosen.out is None else str(chosen.out),
                               backend=chosen.backend, cells=chosen.cells, policy=chosen.policy, seed=chosen.seed,
                               confirm=chosen.confirm, timeout_s=chosen.timeout_s, plans=chosen.plans,
                               connect=tuple(chosen.connect),
                               cell=CellSettings(cell_seed=chosen.seed) if chosen.cell is None else chosen.cell)
    return SessionResult(**run(settings))  # type: ignore[typeddict-item]


@dataclass(frozen=True)
class RunFolder:
    """A session's run folder, read back.

    ``settings``: ``session.json`` (:class:`asp.session.settings.SessionFile`: assembly,
    policy, seed, the cells' settings, status, and once done the result and timings);
    ``experiments``: the finished experiments of ``journal.jsonl`` in order (part, hole,
    result, cell, evidence, wall time); ``learned``: ``learned.lp`` (None until the
    session finished); ``recordings``: the Rerun recordings ``*.rrd``.
    """

    path: Path
    settings: SessionFile
    experiments: list[JournalEntry]
    learned: Path | None
    recordings: list[Path]

    @property
    def fits(self) -> list[tuple[str, str]]:
        """The pairs found to fit (empty until the session finished)."""
        return [] if self.settings.fits is UNSET else list(self.settings.fits)


def read_run(folder: str | Path) -> RunFolder:
    """Read a run folder written by a session; PlannerError naming the file and the field
    when it holds no ``session.json`` or one a session did not write."""
    path = Path(folder)
    settings = read_session_file(path)
    learned = path / "learned.lp"
    return RunFolder(path=path, settings=settings, experiments=read_journal(path / JOURNAL_NAME),
                     learned=learned if learned.is_file() else None, recordings=sorted(path.glob("*.rrd")))
