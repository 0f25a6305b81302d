"""The size-learning session (paper 2.2): which part fits which hole, by experiments.

Each decision is one solve of the policy's entry encoding (``select_<policy>.lp``, which
includes the closure; ``sizes_closure.lp`` for a policy that chooses in Python) over the
parts, holes, their index order, the policy's session facts and the kept observations
``observed(P,H,R)``, in one of two ways by the size of the product:

- up to ``GROUND_ONCE_PAIRS`` part-hole pairs, ONE long-lived ``clingo.Control`` is
  grounded once with every possible observation as an ``#external`` switched by
  ``assign_external``: a decision is one solve (0.2 ms at 5×5);
- above, each decision grounds a fresh ``Control`` with the kept observations as facts:
  the closure is then stratified and derived by the grounder alone, while a program with
  every possible observation external grounds every closure rule over every triple and
  solves through their positive loops (at 20×20 three times the time; docs/decisions.md).

The learner never proposes a pair whose result is entailed, and proposes a pair again
only to re-test it: when an answer makes the closure cyclic (noise), the observations
on the cycle are named and re-tested; per pair the majority of its answers is kept
(a tie keeps the latest), so the kept relation never contradicts itself. It is done
when every pair is known and no conflict is left.

What is entailed follows the size model (:mod:`assembly_constraints.asp.sizes.models`; default ``line``, the
paper's): ``section(P,S)`` facts put each part on a section's size line. Observations
that contradict the model cannot be noise once re-tests reproduce them: when every
observation on a cycle has been answered at least twice with one result (or a pair
reached ``max_answers``), the learner names them in one line, moves to the next weaker
model (``line`` -> ``sections`` -> ``pairs``) and asks the pairs the
weaker model no longer entails. ``model_changes`` lists the moves.

A prior from the nominal CAD (``prior``: pairs and results the nominal cross-sections
decide beyond a tolerance, :mod:`assembly_constraints.asp.sizes.cad_prior`) starts the same way: one answer
each, no experiment, re-tested only when a conflict names them.

Demonstrations that say where a part went (``p1@r1``; paper 4.2, last paragraph) are
fits seen before any experiment: ``demonstrated`` pairs start as one ``fit`` answer each,
so the learner starts from their closure, never tries them unless a conflict names them,
and counts no experiment for them.

A wrong answer that other kept observations entail closes a cycle; one that is
*essential* (its pair is unknown without it, ``sizes/essential.lp``) cannot be caught
that way. With ``confirm`` K > 0, once every pair is known each essential observation is
re-tested until its kept result *leads* the other by K+1 answers (noiseless: K extra
answers). The lead is what the answers prove: with flips of probability q the odds of
the kept result are ((1-q)/q)^lead, so fit, no_fit, fit is worth one answer, not two.
Any pair asked more than once is re-tested at once (before unknown pairs) until it
leads by K+1 or has ``max_answers`` answers (then its majority stands); if its kept
result changes, the closure changes, the newly unknown pairs are asked and the
essentials of the new closure are confirmed.
"""

from __future__ import annotations

import random
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass

import clingo

from assembly_constraints.asp import PlannerError
from assembly_constraints.asp.sizes.knowledge import RESULTS, Knowledge, Pair
from assembly_constraints.asp.sizes.models import SizeModel, build_model, weaker
from assembly_constraints.asp.sizes.policies import SelectionPolicy, get_policy
from assembly_constraints.asp.sizes.truth_oracle import Oracle
from assembly_constraints.asp.solve import add_facts, encoding, fact

GROUND_ONCE_PAIRS = 100
"""Products of at most this many part-hole pairs are grounded once with the observations
as externals, larger ones per decision with the observations as facts (module doc; the
two cost the same at 10×10, measured with ``./run.sh bench sizes``)."""

MAX_CONFIRM = 100
"""``confirm`` K is at most this many answers (each essential observation is re-tested
until its result leads by K+1, so K bounds the experiments)."""

_EXTERNALS = "#external observed(P,H,R) : part(P), hole(H), R=(fit;no_fit)."
_SHOW_LINES = "#show lt/3."


@dataclass(frozen=True)
class Experiment:
    """Experiment ``number`` (1-based) inserted ``part`` into ``hole``; ``retest`` if repeated."""

    number: int
    part: str
    hole: str
    result: str
    retest: bool = False

    def as_json(self) -> dict[str, str]:
        return {"part": self.part, "hole": self.hole, "result": self.result}


@dataclass(frozen=True)
class SizeLearningResult:
    """A finished session: the experiments in order and the final knowledge."""

    policy: str
    experiments: tuple[Experiment, ...]
    knowledge: Knowledge
    model: SizeModel

    @property
    def count(self) -> int:
        """Number of experiments run, re-tests included."""
        return len(self.experiments)

    demonstrated: tuple[Pair, ...] = ()
    """Fits seen in demonstrations, which the learner started from."""

    prior: tuple[tuple[Pair, str], ...] = ()
    """Outcomes a prior decided (the nominal CAD), which the learner started from."""

    model_changes: tuple[str, ...] = ()
    """One line per move to a weaker model: the contradicting observations and the models."""

    def facts(self) -> list[clingo.Symbol]:
        """``part/1, hole/1, size_model/1, section/2, demonstrated/2, tried/4, smaller/2,
        fits/2, no_fit/2`` (the project's facts vocabulary)."""
        k = self.knowledge
        atoms = [fact("part", p) for p in k.parts] + [fact("hole", h) for h in k.holes]
        atoms += [fact("size_model", self.model.name)]
        atoms += [fact("section", p, s) for p, s in self.model.sections.items()]
        atoms += [fact("demonstrated", p, h) for p, h in self.demonstrated]
        atoms += [fact("tried", e.number, e.part, e.hole, e.result) for e in self.experiments]
        atoms += [fact("smaller", x, y) for x, y in sorted(k.smaller)]
        atoms += [fact("fits", p, h) for p, h in sorted(k.fits)]
        atoms += [fact("no_fit", p, h) for p, h in sorted(k.no_fit)]
        return atoms


@dataclass(frozen=True)
class LearningOptions:
    """What a size learner knows before its first experiment and how sure it must be.

    ``confirm`` K ≥ 0 [answers]: each essential observation's kept result must lead the
    other by K+1 answers (0: no confirmation); ``max_answers`` [answers] caps the answers per
    pair, at least K+1 (None: 5, or 4K+1 if more); ``demonstrated``: (part, hole) pairs
    demonstrations placed, known to fit (module doc); ``model``: the size model over the
    parts (None: the paper's ``line``); ``prior``: ((part, hole), result) outcomes known
    before any experiment."""

    max_answers: int | None = None
    confirm: int = 0
    demonstrated: Sequence[Pair] = ()
    model: SizeModel | None = None
    prior: Sequence[tuple[Pair, str]] = ()


class SizeLearner:
    """Knowledge of one learning session and the choice of its next experiments."""

    def __init__(
        self,
        parts: Sequence[str],
        holes: Sequence[str],
        policy: str | SelectionPolicy = "systematic",
        seed: int = 0,
        options: LearningOptions = LearningOptions(),
    ) -> None:
        """``parts``/``holes`` in index order; ``policy`` chooses the experiments, with its
        random ``seed``; ``options``: :class:`LearningOptions`."""
        max_answers, confirm, demonstrated, model, prior = (options.max_answers, options.confirm,
                                                            options.demonstrated, options.model, options.prior)
        if len(set(parts) | set(holes)) != len(parts) + len(holes):
            raise PlannerError("parts and holes need distinct ids")
        if not 0 <= confirm <= MAX_CONFIRM:
            raise PlannerError(f"confirm {confirm}: expected a number of answers from 0 to {MAX_CONFIRM}")
        max_answers = max(5, 4 * confirm + 1) if max_answers is None else max_answers
        if max_answers <= confirm:
            raise PlannerError(f"max_answers {max_answers}: confirm {confirm} needs at least "
                               f"{confirm + 1} answers per pair")
        self.parts, self.holes = tuple(parts), tuple(holes)
        self.demonstrated = tuple(dict.fromkeys(demonstrated))
        outside = [f"{p}@{h}" for p, h in self.demonstrated if p not in self.parts or h not in self.holes]
        if outside:
            raise PlannerError(f"demonstrated placement(s) {' '.join(outside[:5])}: expected a part of "
                               f"{' '.join(self.parts)} and a hole of {' '.join(self.holes)}")
        self.prior = tuple(dict.fromkeys((pair, result) for pair, result in prior))
        unknown = [f"{p}->{h} {r}" for (p, h), r in self.prior
                   if p not in self.parts or h not in self.holes or r not in RESULTS]
        if unknown:
            raise PlannerError(f"prior outcome(s) {' '.join(unknown[:5])}: expected a part of {' '.join(self.parts)}, "
                               f"a hole of {' '.join(self.holes)} and a result in {RESULTS}")
        self.policy = get_policy(policy) if isinstance(policy, str) else policy
        self.model = self._initial_model = build_model("line", self.parts) if model is None else model
        if set(self.model.sections) != set(self.parts):
            raise PlannerError("size model: expected a section for every part and no other")
        self.model_changes: list[str] = []
        self.seed = seed
        self.rng = random.Random(seed)
        self.max_answers, self.confirm = max_answers, confirm
        self.experiments: list[Experiment] = []
        self.answers: dict[Pair, list[str]] = {}
        self.retests: list[Pair] = []
        self._essential: tuple[Pair, ...] = ()
        self._history: list[tuple[Knowledge, Pair | None, list[Pair], tuple[Pair, ...]]] = []
        self._pairs = [(p, h) for p in self.parts for h in self.holes]
        self._prepare_model()
        self._selected: Pair | None = None
        self._start_from_demonstrations()

    def _prepare_model(self) -> None:
        """Prepare the policy and the facts every solve shares for the current model
        (again only when the model is weakened)."""
        if self.policy.prepare is not None:
            for size in sorted({len(parts) for parts in self.model.groups().values()}):
                self.policy.prepare(size, len(self.holes))
        self._static = self._static_facts(self.seed)
        self._decoded: dict[clingo.Symbol, tuple[str, tuple[str, ...]]] = {}
        self._ctl: clingo.Control | None = None
        if len(self._pairs) <= GROUND_ONCE_PAIRS:
            self._ctl = self._grounded([], _EXTERNALS)
            self._literals = {(*pair, r): self._literal(fact("observed", *pair, r))
                              for pair in self._pairs for r in RESULTS}

    def _grounded(self, observed: list[clingo.Symbol], rules: str = "") -> clingo.Control:
        """A Control grounded on the shared facts, the ``observed`` facts, the learner's
        own ``rules`` and the policy's encodings."""
        ctl = clingo.Control(["--warn=none", *self.policy.solver_options])
        add_facts(ctl, [*self._static, *observed])
        ctl.add("base", [], rules + _SHOW_LINES)
        for name in [self.policy.encoding or "sizes_closure.lp"] + (["sizes/essential.lp"] if self.confirm else []):
            ctl.load(str(encoding(name)))
        ctl.ground([("base", [])])
        return ctl

    def _literal(self, atom: clingo.Symbol) -> int:
        """The solver literal of a ground ``#external`` atom."""
        assert self._ctl is not None
        found = self._ctl.symbolic_atoms[atom]
        if found is None:
            raise PlannerError(f"{atom}: not declared as an external of the learner's program")
        return found.literal

    def _start_from_demonstrations(self) -> None:
        """One ``fit`` answer per demonstrated pair and one per prior outcome, then the
        closure; a prior that contradicts the model is weakened away as any observation."""
        for pair, result in [*((pair, "fit") for pair in self.demonstrated), *self.prior]:
            self.answers[pair] = [result]
            self._set_observation(pair, result)
        self.knowledge = self._solve()

    def _decode(self, symbol: clingo.Symbol) -> tuple[str, tuple[str, ...]]:
        """``(name, argument strings)`` of a shown atom, cached (reading arguments through
        clingo's API costs more than a solve on small instances)."""
        entry = self._decoded.get(symbol)
        if entry is None:
            entry = self._decoded[symbol] = (symbol.name, tuple(str(a) for a in symbol.arguments))
        return entry

    def _static_facts(self, seed: int) -> list[clingo.Symbol]:
        """The parts, holes, their index order, sections and the policy's session facts."""
        atoms = [fact("part", p) for p in self.parts] + [fact("hole", h) for h in self.holes]
        atoms += [fact("part_index", p, i) for i, p in enumerate(self.parts, 1)]
        atoms += [fact("hole_index", h, j) for j, h in enumerate(self.holes, 1)]
        atoms += [fact("section", p, section) for p, section in self.model.sections.items()]
        if self.policy.session_facts is not None:
            atoms += self.policy.session_facts(self.parts, self.holes, seed)
        return atoms

    def _solve(self) -> Knowledge:
        """Solve the policy's program on the kept observations; remember
        ``select/2`` and ``essential/2`` (index order)."""
        ctl = self._ctl
        if ctl is None:
            ctl = self._grounded([fact("observed", p, h, self._kept(answers))
                                  for (p, h), answers in self.answers.items() if answers])
        last: list[clingo.Symbol] = []
        result = ctl.solve(on_model=lambda m: last.__setitem__(slice(None), m.symbols(shown=True)))
        if not result.satisfiable:
            raise PlannerError(f"policy {self.policy.name}: no model for the current knowledge")
        entries = [self._decode(symbol) for symbol in last]
        knowledge = Knowledge.from_entries(self.parts, self.holes, entries, tuple(self.model.sections.items()))
        selected = [(args[0], args[1]) for name, args in entries if name == "select"]
        self._selected = selected[0] if len(selected) == 1 else None
        essential = {(args[0], args[1]) for name, args in entries if name == "essential"}
        self._essential = tuple(pair for pair in self._pairs if pair in essential)
        return knowledge

    def _set_observation(self, pair: Pair, result: str | None) -> None:
        """Switch the externals of ``pair`` to ``result`` (None: no observation) in a program
        grounded once; a program grounded per decision reads the kept answers instead."""
        if self._ctl is not None:
            for value in RESULTS:
                self._ctl.assign_external(self._literals[(*pair, value)], value == result)

    @staticmethod
    def _kept(answers: list[str]) -> str:
        """The majority answer; a tie keeps the latest."""
        counts = {r: answers.count(r) for r in RESULTS}
        if counts["fit"] == counts["no_fit"]:
            return answers[-1]
        return max(RESULTS, key=counts.__getitem__)

    def lead(self, pair: Pair) -> int:
        """Answers of ``pair`` agreeing with its kept result minus those disagreeing (0 if none)."""
        answers = self.answers.get(pair, [])
        return 2 * answers.count(self._kept(answers)) - len(answers) if answers else 0

    def _unconfirmed(self, pair: Pair) -> bool:
        """``pair`` leads by ``confirm`` answers or fewer and may still be re-tested."""
        return self.lead(pair) <= self.confirm and len(self.answers.get(pair, [])) < self.max_answers

    def essential(self) -> list[Pair]:
        """Observed pairs that become unknown when their observation alone is removed
        (index order; computed only with ``confirm`` > 0 and an acyclic closure)."""
        return list(self._essential)

    def _due_retests(self) -> list[Pair]:
        """Queued re-tests (conflicts, re-tests to confirm), else (``confirm`` > 0, every
        pair known) the unconfirmed essential observations."""
        if self.retests or not self.confirm or not self.knowledge.complete:
            return list(self.retests)
        return [pair for pair in self._essential if self._unconfirmed(pair)]

    def next_experiment(self) -> Pair | None:
        """The pair to try next (a due re-test first); None when learning is done."""
        due = self._due_retests()
        if due:
            return due[0]
        if self.knowledge.complete:
            return None
        pair: Pair | None = self.policy.choose(self.knowledge, self.rng) if self.policy.choose else self._selected
        if pair is None or self.knowledge.result(*pair) is not None:
            raise PlannerError(f"policy {self.policy.name} chose {pair}, not an unknown pair")
        return pair

    def record(self, part: str, hole: str, result: str) -> Experiment:
        """Add one answer, update the closure, queue re-tests (conflicts; unconfirmed re-tested pairs)."""
        self._check_answer(part, hole, result)
        self._history.append((self.knowledge, self._selected, list(self.retests), self._essential))
        experiment = self._add_answer(part, hole, result)
        self.knowledge = self._solve()
        self._queue_retests((part, hole))
        return experiment

    def record_all(self, results: Sequence[tuple[str, str, str]]) -> list[Experiment]:
        """:meth:`record` for experiments that finished together: every answer is added
        in the order given, then the closure is solved once (the same closure as recording
        them one by one: it depends only on each pair's kept answer) and re-tests are
        queued; a conflict is judged on the state after all of them. :meth:`undo` cannot
        take back a batch of more than one."""
        if len(results) == 1:
            return [self.record(*results[0])]
        for answer in results:
            self._check_answer(*answer)
        self._history.clear()
        recorded = [self._add_answer(*answer) for answer in results]
        self.knowledge = self._solve()
        for experiment in recorded:
            self._queue_retests((experiment.part, experiment.hole))
        return recorded

    def _check_answer(self, part: str, hole: str, result: str) -> None:
        if result not in RESULTS or part not in self.parts or hole not in self.holes:
            raise PlannerError(f"experiment ({part},{hole}) -> {result!r}: expected a known "
                               f"part, hole and a result in {RESULTS}")

    def _add_answer(self, part: str, hole: str, result: str) -> Experiment:
        """Append the experiment and its answer; switch the pair's external to its kept answer."""
        pair = (part, hole)
        retest = pair in self.answers
        if pair in self.retests:
            self.retests.remove(pair)
        experiment = Experiment(len(self.experiments) + 1, part, hole, result, retest)
        self.experiments.append(experiment)
        self.answers.setdefault(pair, []).append(result)
        self._set_observation(pair, self._kept(self.answers[pair]))
        return experiment

    def _contradicts_model(self) -> bool:
        """The observations on a cycle are no noise: each pair on it answered at least
        twice with one result, or one pair ``max_answers`` times."""
        pairs = {(p, h) for p, h, _ in self.knowledge.conflicts}
        if not pairs:
            return False
        answers = [self.answers[pair] for pair in pairs]
        reproduced = all(len(a) >= 2 and len(set(a)) == 1 for a in answers)
        return reproduced or any(len(a) >= self.max_answers for a in answers)

    def _weaken(self) -> None:
        """Move to the next weaker model and re-apply every kept answer;
        PlannerError when no weaker model is left (the kept answers contradict themselves)."""
        named = ", ".join(f"{p}->{h} {r}" for p, h, r in sorted(self.knowledge.conflicts))
        following = weaker(self.model)
        if following is None:
            raise PlannerError(f"observations stay in conflict under size model {self.model.name}: {named}")
        change = f"observations {named} contradict size model {self.model.name}; now {following.name}"
        self.model_changes.append(change)
        self.model = following
        self._prepare_model()
        for pair, answers in self.answers.items():
            self._set_observation(pair, self._kept(answers))
        self.retests = [pair for pair in self.retests if pair in self.answers and len(set(self.answers[pair])) > 1]
        self._history.clear()
        self.knowledge = self._solve()

    def conflicting_experiments(self) -> list[Experiment]:
        """Experiments whose kept result lies on a cycle of the closure."""
        kept = {(p, h, r) for p, h, r in self.knowledge.conflicts}
        return [e for e in self.experiments if (e.part, e.hole, e.result) in kept]

    def _queue_retests(self, recorded: Pair) -> None:
        """Queue the observations on a cycle and, with ``confirm`` > 0, the ``recorded``
        pair if it is a re-test still unconfirmed."""
        while self._contradicts_model():
            self._weaken()
        for p, h, _ in sorted(self.knowledge.conflicts):
            if (p, h) not in self.retests:
                self.retests.append((p, h))
        if (self.confirm and len(self.answers[recorded]) > 1 and self._unconfirmed(recorded)
                and recorded not in self.retests):
            self.retests.append(recorded)

    def next_batch(self, size: int, pending: Sequence[Pair] = ()) -> list[Pair]:
        """Up to ``size`` pairs to try in parallel, none of whose outcomes can entail another's.

        ``pending`` are pairs already out at other cells: the new pairs must be
        independent of them too. Due re-tests (conflicts, ties, confirmations) not
        pending come first. Otherwise pairs are added one at a time, each the first of
        :meth:`_candidates` that no combination of outcomes of the pending and already
        chosen pairs entails or contradicts, nor its outcomes theirs (:meth:`_independent`).
        """
        retests = [p for p in self._due_retests() if p not in pending]
        if retests:
            return retests[:size]
        if self.knowledge.complete:
            return []
        # the policy's own choice leads a batch beside nothing (a ranking beside pending pairs
        # replaces it); taken before hypothetical solves replace the selection
        choice = self.next_experiment() if self.policy.batch_rank is None or not pending else None
        chosen: list[Pair] = []
        while len(chosen) < size:
            out = [*pending, *chosen]
            pair = next((p for p in self._candidates(choice, out) if self._independent([*out, p])), None)
            if pair is None:
                break
            chosen.append(pair)
        return chosen

    def _candidates(self, choice: Pair | None, out: list[Pair]) -> Iterator[Pair]:
        """Unknown pairs not in ``out``, best first for a batch beside ``out``: the
        policy's ``batch_rank`` given ``out`` if it has one (with nothing out, its
        ``choice`` first), else its ``choice``, then index order. Lazy: the ranking is
        computed only when the first candidate is not taken."""
        rank = self.policy.batch_rank
        seen = set(out)
        if choice is not None and (rank is None or not out) and choice not in seen:
            seen.add(choice)
            yield choice
        for pair in self.knowledge.unknown if rank is None else rank(self.knowledge, out):
            if pair not in seen:
                seen.add(pair)
                yield pair

    def _independent(self, pairs: list[Pair]) -> bool:
        """No outcomes of all but one pair entail (or contradict) the remaining pair.

        The closure is transitive over the parts and holes of one section's line
        (eqs. 2-5; pairs of other sections are unrelated), so some outcomes of the
        others entail ``(p, h)`` exactly when the graph of the known ``smaller/2`` edges
        plus each other pair as an edge in either direction has a path from p to h or
        from h to p (a shortest such walk is a simple path, which turns each pair one way
        only). A contradiction is a cycle through some pair, i.e. the rest of the cycle
        entails that pair: the same test. Linear in the graph per pair (solving every
        combination of the others' outcomes instead would be exponential in the batch size).
        """
        known: dict[str, dict[str, set[str]]] = {}
        for section, smaller, bigger in self.knowledge.lines:
            known.setdefault(section, {}).setdefault(smaller, set()).add(bigger)
        section_of = self.model.sections
        for index, (part, hole) in enumerate(pairs):
            line = section_of[part]
            graph = {node: set(targets) for node, targets in known.get(line, {}).items()}
            for other_part, other_hole in pairs[:index] + pairs[index + 1:]:
                if section_of[other_part] != line:
                    continue
                graph.setdefault(other_part, set()).add(other_hole)
                graph.setdefault(other_hole, set()).add(other_part)
            if _reaches(graph, part, hole) or _reaches(graph, hole, part):
                return False
        return True

    def _restore(self, pair: Pair) -> None:
        """Set ``pair`` back to its kept observation (or none)."""
        answers = self.answers.get(pair)
        self._set_observation(pair, self._kept(answers) if answers else None)

    def undo(self) -> None:
        """Take back the last experiment (walks of a policy's decision tree use this)."""
        if not self._history:
            raise PlannerError("undo: nothing to take back (a model change or a batch recorded "
                               "at once forgets the history)")
        last = self.experiments.pop()
        pair = (last.part, last.hole)
        self.answers[pair].pop()
        if not self.answers[pair]:
            del self.answers[pair]
        self._restore(pair)
        self.knowledge, self._selected, self.retests, self._essential = self._history.pop()

    def reset(self, seed: int = 0) -> None:
        """Forget all observations: a fresh session on the same product and policy.

        ``seed`` reseeds Python policies; ``session_facts`` (e.g. random priorities)
        stay those of the seed given at construction; a weakened model is restored.
        """
        for pair in self.answers:
            self._set_observation(pair, None)
        if self.model != self._initial_model:
            self.model, self.model_changes = self._initial_model, []
            self._prepare_model()
        self.experiments, self.answers, self.retests, self._history = [], {}, [], []
        self.rng = random.Random(seed)
        self._start_from_demonstrations()

    def result(self) -> SizeLearningResult:
        return SizeLearningResult(self.policy.name, tuple(self.experiments), self.knowledge, self.model,
                                  self.demonstrated, self.prior, tuple(self.model_changes))


def _reaches(graph: dict[str, set[str]], start: str, goal: str) -> bool:
    """Whether ``goal`` can be reached from ``start`` along the graph's edges."""
    seen, frontier = {start}, [start]
    while frontier:
        for node in graph.get(frontier.pop(), ()):
            if node == goal:
                return True
            if node not in seen:
                seen.add(node)
                frontier.append(node)
    return False


def learn_sizes(
    parts: Sequence[str],
    holes: Sequence[str],
    oracle: Oracle,
    policy: str | SelectionPolicy = "systematic",
    seed: int = 0,
    on_experiment: Callable[[Experiment, Knowledge], None] | None = None,
    options: LearningOptions = LearningOptions(),
) -> SizeLearningResult:
    """Run experiments chosen by ``policy`` against ``oracle`` until every pair is known
    (and, with ``options.confirm`` > 0, every essential observation confirmed), starting
    from the fits ``options.demonstrated``, under the size ``options.model``; see
    :class:`SizeLearner`."""
    learner = SizeLearner(parts, holes, policy, seed, options)
    return run_learner(learner, oracle, on_experiment)


def run_learner(
    learner: SizeLearner,
    oracle: Oracle,
    on_experiment: Callable[[Experiment, Knowledge], None] | None = None,
) -> SizeLearningResult:
    """Ask ``oracle`` the learner's experiments, one at a time, until it is done."""
    while (pair := learner.next_experiment()) is not None:
        experiment = learner.record(*pair, oracle.ask(*pair))
        if on_experiment is not None:
            on_experiment(experiment, learner.knowledge)
    return learner.result()
