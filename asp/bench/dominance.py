"""Can a policy beat ``systematic`` somewhere without losing anywhere? Exhaustive answers.

Question. A policy asks experiments (part p, hole h) → fit / no fit until the closure
entails every pair. ``systematic`` asks the unknown pair of lowest part, then lowest
hole index; let b(t) be its number of experiments on the truth t. Over a set T of
truths, what is the least total number of experiments of a policy whose count on
every t ∈ T is ≤ b(t) (a policy *never worse than systematic* on T)? It is at most
Σ b(t) (systematic itself); when it equals Σ b(t), every such policy needs exactly b(t)
on every t: beating systematic on one truth forces losing on another (systematic is
Pareto-minimal on T).

Search. Knowledge is the closed set of known fits and no-fits. The closure is that of
biorders: a pair is entailed iff every biorder agreeing with the answers agrees on it
(path closure of "p < h" for a fit, "h ≤ p" for a no-fit; :func:`add_answer`), so a
policy stops, as a real one does, only when a single biorder of all m×n remains.
Every truth t has a *reduction* R(t): its pairs not entailed by its other pairs. They
must all be asked, and every experiment is either one of them or *wasted* for t, so
experiments(t) = |R(t)| + waste(t), and the deadline b(t) leaves t a slack
b(t) − |R(t)| of waste. The least total waste below a (knowledge, depth) state is
the least, over the experiments wasted for no alive truth without slack left, of
(its waste + the least waste below each answer); :class:`BranchAndBound` computes it
by a memoised, bounded depth-first search that stores proven lower bounds (raised by
iterative deepening when time-limited). :class:`Search` is that problem over a set of
truths with per-truth deadlines; without deadlines it gives the unconstrained optimum.

Relaxation for Cranfield. With T = the 900 distinct 5×5 Cranfield truths (14400
relabelings, each truth 16 times, so means over T equal means over the 14400), the
knowledge, entailment and stopping range over all 329 462 5×5 biorders, but deadlines
and objective only over T; subtrees holding no truth of T cost nothing. A policy
never worse than systematic on every biorder is never worse on T, and its cost over
T is counted exactly, so the least total over T is a lower bound for every such
policy. A policy found in the relaxation (the search's first policy) is, conversely,
a decision tree over all 5×5 biorders that is never worse than systematic on every
Cranfield relabeling; :func:`policy_counts` replays it.

Bound over all 5×5 biorders. :class:`Relaxation` keeps the deadlines of all 329 462
biorders while a Cranfield truth is alive (dropping them where none is, and dropping
biorders that can no longer overrun) and counts the Cranfield truths only: a lower
bound of the Cranfield total of every policy never worse than systematic on every
5×5 biorder. ``./run.sh bench dominance --help`` lists the computations.
"""

from __future__ import annotations

import argparse
import time
from abc import ABC, abstractmethod
from dataclasses import dataclass
from typing import Generic, NamedTuple, TypeVar

import numpy as np

from asp.sizes.biorders import all_biorders, mask_bits
from asp.sizes.evaluate import relabeled_matrices
from asp.sizes.truth_oracle import TruthOracle
from bridge.cli_types import ArgumentParser, comma_list, finite_float, int_in, size_pair

INFEASIBLE = 1 << 40
"""Value of a state from which no policy meets every deadline."""

def add_answer(fit: int, no_fit: int, m: int, n: int, bit: int, fits: bool) -> tuple[int, int]:
    """Closure of closed knowledge (fit, no_fit masks, bit p·n+h) plus one answer.

    A fit p → h (p < h) and a no-fit h → p (h ≤ p) are arcs of an acyclic relation on
    parts and holes; a pair is entailed iff a path joins its ends. The new paths use the
    new arc once: (what reaches its tail) × (what its head reaches).
    """
    part, hole = divmod(bit, n)
    rows_fit = [(fit >> (p * n)) & ((1 << n) - 1) for p in range(m)]
    rows_no = [(no_fit >> (p * n)) & ((1 << n) - 1) for p in range(m)]
    if fits:  # tail: parts ≤ part and holes ≤ part; head: holes ≥ hole and parts ≥ hole
        tail_parts = [p for p in range(m) if p == part or rows_fit[p] & rows_no[part]]
        tail_holes = rows_no[part]
        head_parts = [p for p in range(m) if (rows_no[p] >> hole) & 1]
        head_holes = 1 << hole
        for p in head_parts:
            head_holes |= rows_fit[p]
    else:  # tail: parts < hole and holes ≤ hole; head: parts ≥ part and holes > part
        tail_parts = [p for p in range(m) if (rows_fit[p] >> hole) & 1]
        tail_holes = 1 << hole
        for p in tail_parts:
            tail_holes |= rows_no[p]
        head_parts = [p for p in range(m) if p == part or rows_fit[part] & rows_no[p]]
        head_holes = rows_fit[part]
    for p in tail_parts:
        rows_fit[p] |= head_holes
    for p in head_parts:
        rows_no[p] |= tail_holes
    return (sum(r << (p * n) for p, r in enumerate(rows_fit)),
            sum(r << (p * n) for p, r in enumerate(rows_no)))


def reductions(truths: np.ndarray, m: int, n: int) -> np.ndarray:
    """Mask of each biorder's pairs not entailed by its other pairs (uint64 per truth).

    A fit (p, h) is entailed iff some p' fits h and p fits a hole p' does not; a no-fit
    (p, h) iff some p' misses h and fits a hole p misses.
    """
    rows = [(truths >> np.uint64(p * n)) & np.uint64((1 << n) - 1) for p in range(m)]
    reduced = np.zeros(len(truths), dtype=np.uint64)
    for p in range(m):
        for h in range(n):
            bit = np.uint64(1 << h)
            fit_implied = np.zeros(len(truths), dtype=bool)
            no_fit_implied = np.zeros(len(truths), dtype=bool)
            for q in range(m):
                fit_implied |= ((rows[q] & bit) != 0) & ((rows[p] & ~rows[q]) != 0)
                no_fit_implied |= ((rows[q] & bit) == 0) & ((rows[q] & ~rows[p]) != 0)
            implied = np.where((rows[p] & bit) != 0, fit_implied, no_fit_implied)
            reduced |= np.where(implied, np.uint64(0), np.uint64(1 << (p * n + h)))
    return reduced


def systematic_counts(truths: np.ndarray, m: int, n: int) -> np.ndarray:
    """Experiments ``systematic`` needs on each truth (walking its decision tree once)."""
    counts = np.zeros(len(truths), dtype=np.int64)
    stack = [(0, 0, np.arange(len(truths)))]
    while stack:
        fit, no_fit, members = stack.pop()
        if fit | no_fit == (1 << (m * n)) - 1:
            continue
        bit = next(q for q in range(m * n) if not ((fit | no_fit) >> q) & 1)
        counts[members] += 1
        fits = ((truths[members] >> np.uint64(bit)) & np.uint64(1)).astype(bool)
        for answer, part in ((True, members[fits]), (False, members[~fits])):
            if len(part):
                stack.append((*add_answer(fit, no_fit, m, n, bit, answer), part))
    return counts


def bit_set(flags: np.ndarray) -> int:
    """The booleans as one integer bit set (bit i = flags[i])."""
    return int.from_bytes(np.packbits(flags, bitorder="little").tobytes(), "little")


Key = tuple[int, int, int]
"""A state's memo key: (fit mask, no-fit mask, depth). The depth is part of it since the
waste left to the truths alive depends on it (their deadlines count from the root)."""

S = TypeVar("S")
"""The state type of a problem."""


@dataclass(slots=True)
class Option(Generic[S]):
    """One experiment at a state: its ``waste`` now, the states after it (one per answer)
    and their ``parts`` (lower bounds, exact values once solved); ``lower`` = waste + Σ parts."""

    bit: int
    waste: int
    children: list[S]
    parts: list[int]
    lower: int


class BranchAndBound(ABC, Generic[S]):
    """Least total waste below a state, by memoised depth-first branch and bound.

    A problem supplies its states and four things: :meth:`key` (the memo key),
    :meth:`settled` (nothing more to count below: value 0), :meth:`askable` (the unknown
    experiments wasted for no alive truth without slack, with the waste they count) and
    :meth:`children` (the states after an experiment, one per answer that matters). The
    value of a state is min over askable experiments of (waste + Σ values of its
    children), INFEASIBLE if none is askable.

    ``memo[key]`` = (value, True) once proven exact, (lower bound, False) before;
    ``choice[key]`` is the experiment (bit) of the last policy found within the bound;
    ``states`` counts the expanded states. With ``first_only`` (:meth:`first_policy`) the
    first policy within the bound is taken, and its values, not proven least, go to
    ``found`` instead of ``memo``.
    """

    base = 0
    """Experiments every policy asks (the counted reductions): the total is base + waste."""

    def __init__(self) -> None:
        self.states = 0
        self.memo: dict[Key, tuple[int, bool]] = {}
        self.choice: dict[Key, int] = {}
        self.found: dict[Key, int] = {}
        self.first_only = False

    @abstractmethod
    def root(self) -> S:
        """The state before any experiment."""

    @abstractmethod
    def key(self, state: S) -> Key:
        """The memo key of a state."""

    @abstractmethod
    def settled(self, state: S) -> bool:
        """Whether nothing more is counted below the state (its value is 0)."""

    @abstractmethod
    def askable(self, state: S) -> list[tuple[int, int]]:
        """(bit, counted waste) of each askable experiment, in bit order."""

    @abstractmethod
    def children(self, state: S, bit: int) -> list[S]:
        """The states after asking ``bit``, one per answer of some alive truth that matters."""

    def least_total(self, bound: int | None = None) -> int:
        """Least total if ≤ ``bound`` (default: none), else a lower bound > it."""
        limit = INFEASIBLE - 1 if bound is None else bound - self.base
        return self.base + self.solve(self.root(), limit)

    def first_policy(self) -> int:
        """Total of the first policy found (INFEASIBLE if none), trying experiments of
        least bounded waste first; see ``choice``.

        Its values are kept apart from ``memo``, which holds proven bounds only.
        """
        self.first_only = True
        try:
            return self.least_total()
        finally:
            self.first_only = False

    def lower_bound_within(self, seconds: float) -> tuple[int, bool]:
        """Raise a proven lower bound of the least total by iterative deepening for about
        ``seconds`` (checked between rounds); (bound, True) once it is the least total."""
        start, root = time.perf_counter(), self.root()
        bound = self.lower_bound(root)
        while time.perf_counter() - start < seconds:
            value = self.solve(root, bound)
            if value <= bound:
                return self.base + value, True
            bound = value
        return self.base + bound, False

    def lower_bound(self, state: S) -> int:
        """Stored bound of a state, else the least waste of its next experiment (memoised).

        A settled state costs nothing more; a state with no askable experiment (every
        one wastes an alive truth without slack) is infeasible.
        """
        if self.settled(state):
            return 0
        key = self.key(state)
        known = self.memo.get(key)
        if known is not None:
            return known[0]
        least = min((waste for _, waste in self.askable(state)), default=INFEASIBLE)
        self.memo[key] = (least, False)
        return least

    def solve(self, state: S, bound: int) -> int:
        """Least waste below ``state`` if ≤ bound, else a lower bound > bound.

        Experiments are tried by increasing lower bound; a child is solved within what
        the bound leaves after the waste and the other children's bounds, and an
        experiment is dropped as soon as its total exceeds the bound. A policy found
        lowers the bound to its total − 1, so later ones must be strictly better.
        """
        if self.settled(state):
            return 0
        key = self.key(state)
        known = self.memo.get(key)
        if known is not None and (known[1] or known[0] > bound):
            return known[0]
        if self.first_only and key in self.found:
            return self.found[key]
        self.states += 1
        options: list[Option[S]] = []
        for bit, waste in self.askable(state):
            children = self.children(state, bit)
            parts = [self.lower_bound(child) for child in children]
            options.append(Option(bit, waste, children, parts, waste + sum(parts)))
        options.sort(key=lambda option: option.lower)
        best = INFEASIBLE
        for option in options:
            if option.lower > bound:
                break
            parts = option.parts
            for i, child in enumerate(option.children):
                parts[i] = self.solve(child, bound - option.waste - sum(parts) + parts[i])
                if option.waste + sum(parts) > bound:
                    break
            option.lower = total = option.waste + sum(parts)
            if total <= bound:
                best, bound = total, total - 1
                self.choice[key] = option.bit
                if self.first_only:
                    break
        if best < INFEASIBLE:
            if self.first_only:
                self.found[key] = best
            else:
                self.memo[key] = (best, True)
            return best
        lower = min((option.lower for option in options), default=INFEASIBLE)
        self.memo[key] = (lower, False)
        return lower


class SearchState(NamedTuple):
    """A state of :class:`Search`: the knowledge, the truths alive and their slack levels."""

    fit: int
    no_fit: int
    depth: int
    alive: int
    """Bit set of the truths consistent with the knowledge."""
    levels: tuple[int, ...]
    """``levels[k]``: bit set of the alive truths with k wastes left (those without deadline in none)."""


class Search(BranchAndBound[SearchState]):
    """Least total waste over policies meeting per-truth deadlines (see module docstring).

    ``truths`` are m×n biorder masks (uint64); ``slack[i]`` the waste truth i may have,
    None for no deadline. Truths are bit sets (bit i = truth i) over the truth indices.
    A state with one truth alive is settled: it asks that truth's reduction.
    """

    def __init__(self, m: int, n: int, truths: np.ndarray, slack: list[int | None]) -> None:
        super().__init__()
        self.m, self.n, self.truths, self.slack = m, n, truths, slack
        pairs = m * n
        reduced = reductions(truths, m, n)
        self.base = int(np.bitwise_count(reduced).sum())
        self.fit_sets = [bit_set(column) for column in mask_bits(truths, pairs).T]
        self.reduced_sets = [bit_set(column) for column in mask_bits(reduced, pairs).T]
        self.top = max((s for s in slack if s is not None), default=0)
        levels = np.array([-1 if s is None else s for s in slack])
        self.levels = tuple(bit_set(levels == k) for k in range(self.top + 1))

    def root(self) -> SearchState:
        return SearchState(0, 0, 0, (1 << len(self.truths)) - 1, self.levels)

    def least_total(self, bound: int | None = None) -> int:
        """Least total experiments over the truths if ≤ ``bound`` (default: none), else a
        lower bound > it; INFEASIBLE at once if some deadline is below its reduction."""
        if any(s is not None and s < 0 for s in self.slack):
            return INFEASIBLE
        return super().least_total(bound)

    def key(self, state: SearchState) -> Key:
        return state.fit, state.no_fit, state.depth

    def settled(self, state: SearchState) -> bool:
        return state.alive & (state.alive - 1) == 0

    def askable(self, state: SearchState) -> list[tuple[int, int]]:
        """Unknown pairs wasted for no truth without slack; waste = alive truths outside whose reduction they are."""
        known, alive, tight = state.fit | state.no_fit, state.alive, state.levels[0]
        return [(bit, (alive & ~self.reduced_sets[bit]).bit_count()) for bit in range(self.m * self.n)
                if not (known >> bit) & 1 and not tight & ~self.reduced_sets[bit]]

    def children(self, state: SearchState, bit: int) -> list[SearchState]:
        """One state per answer some alive truth gives; the truths for which ``bit`` is
        wasted move down one slack level (off the last one: out of every level)."""
        fit, no_fit, depth, alive, levels = state
        wasted = alive & ~self.reduced_sets[bit]
        result = []
        for answer, members in ((True, alive & self.fit_sets[bit]), (False, alive & ~self.fit_sets[bit])):
            if members:
                moved = tuple(
                    members & ((levels[k] & ~wasted) | (levels[k + 1] & wasted if k < self.top else 0))
                    for k in range(self.top + 1)
                )
                result.append(SearchState(*add_answer(fit, no_fit, self.m, self.n, bit, answer), depth + 1,
                                          members, moved))
        return result


def policy_counts(search: Search, truths: np.ndarray | None = None) -> np.ndarray:
    """Experiments the policy in ``search.choice`` needs on each truth (default: its own).

    The policy is defined where at least two of ``search.truths`` are alive; with one
    left it asks that truth's reduction in index order, with none (other truths)
    the unknown pair of lowest index, as systematic. Walks the decision tree once over
    ``truths``, with :func:`add_answer`.
    """
    m, n = search.m, search.n
    truths = search.truths if truths is None else truths
    reduced = reductions(search.truths, m, n).tolist()
    counts = np.zeros(len(truths), dtype=np.int64)
    stack = [(0, 0, 0, np.arange(len(truths)), search.root().alive)]
    while stack:
        fit, no_fit, depth, members, alive = stack.pop()
        known = fit | no_fit
        if known == (1 << (m * n)) - 1:
            counts[members] = depth
            continue
        if alive & (alive - 1):
            bit = search.choice[(fit, no_fit, depth)]
        else:
            wanted = reduced[alive.bit_length() - 1] & ~known if alive else 0
            bit = next(q for q in range(m * n) if ((wanted or ~known) >> q) & 1)
        assert not (known >> bit) & 1, "asked an entailed pair"
        fits = ((truths[members] >> np.uint64(bit)) & np.uint64(1)).astype(bool)
        for answer, part in ((True, members[fits]), (False, members[~fits])):
            if len(part):
                stayed = alive & (search.fit_sets[bit] if answer else ~search.fit_sets[bit])
                stack.append((*add_answer(fit, no_fit, m, n, bit, answer), depth + 1, part, stayed))
    return counts


class RelaxationState(NamedTuple):
    """A state of :class:`Relaxation`: the knowledge and the constraining biorders alive."""

    fit: int
    no_fit: int
    depth: int
    alive: np.ndarray
    """Indices of the alive biorders that still constrain (counted, or able to overrun)."""
    slack: np.ndarray
    """Their waste left."""


class Relaxation(BranchAndBound[RelaxationState]):
    """Least counted waste of a policy never worse than systematic on *all* m×n biorders.

    ``slack`` (per biorder of ``all_biorders(m, n)``) is the waste allowed, ``counted``
    marks the biorders whose waste is summed. Relaxed for size: a state where no
    counted biorder is alive costs 0 (its deadlines are dropped), and a biorder that
    can no longer overrun (slack ≥ its unknown pairs outside its reduction) is
    dropped. Every policy meeting all deadlines asks, at each state holding a counted
    biorder, an experiment wasted for no alive biorder without slack, so its counted
    waste is ≥ the value found: a sound lower bound. Index arrays instead of bit sets,
    as 329 462 biorders make bit-set operations slow.
    """

    def __init__(self, m: int, n: int, slack: np.ndarray, counted: np.ndarray) -> None:
        super().__init__()
        self.m, self.n, self.full = m, n, (1 << (m * n)) - 1
        truths = all_biorders(m, n)
        reduced = reductions(truths, m, n)
        self.outside = ~reduced & np.uint64(self.full)
        self.fits = mask_bits(truths, m * n)
        self.wasted = ~mask_bits(reduced, m * n)
        self.slack, self.counted = slack.astype(np.int64), counted
        self.base = int(np.bitwise_count(reduced[counted]).sum())

    def root(self) -> RelaxationState:
        return self.state(0, 0, 0, np.arange(len(self.slack)), self.slack)

    def state(self, fit: int, no_fit: int, depth: int, alive: np.ndarray, slack: np.ndarray) -> RelaxationState:
        """The state, without the biorders that can no longer overrun their deadline."""
        unknown = np.bitwise_count(self.outside[alive] & ~np.uint64(fit | no_fit)).astype(np.int64)
        keep = self.counted[alive] | (slack < unknown)
        return RelaxationState(fit, no_fit, depth, alive[keep], slack[keep])

    def key(self, state: RelaxationState) -> Key:
        return state.fit, state.no_fit, state.depth

    def settled(self, state: RelaxationState) -> bool:
        return not self.counted[state.alive].any() or state.fit | state.no_fit == self.full

    def askable(self, state: RelaxationState) -> list[tuple[int, int]]:
        """Unknown pairs wasted for no alive biorder without slack; waste = counted biorders it is wasted for."""
        wasted = self.wasted[state.alive]
        known = state.fit | state.no_fit
        unknown = np.array([not (known >> q) & 1 for q in range(self.m * self.n)])
        askable = unknown & ~(wasted & (state.slack == 0)[:, None]).any(axis=0)
        waste = (wasted & self.counted[state.alive][:, None]).sum(axis=0)
        return [(bit, int(waste[bit])) for bit in np.flatnonzero(askable).tolist()]

    def children(self, state: RelaxationState, bit: int) -> list[RelaxationState]:
        """One state per answer that leaves a counted biorder alive; the alive biorders for
        which ``bit`` is wasted lose one slack."""
        fit, no_fit, depth, alive, slack = state
        fits, wasted = self.fits[alive, bit], self.wasted[alive, bit]
        return [
            self.state(*add_answer(fit, no_fit, self.m, self.n, bit, answer), depth + 1,
                       alive[side], slack[side] - wasted[side])
            for answer, side in ((True, fits), (False, ~fits))
            if self.counted[alive[side]].any()
        ]


def cranfield_search() -> Search:
    """The relaxation over the 900 distinct Cranfield truths, deadlines from systematic."""
    matrices = set(relabeled_matrices(TruthOracle.from_assembly("cranfield"), "all", seed=0))
    truths = np.array(sorted(bit_set(np.ravel(matrix)) for matrix in matrices), dtype=np.uint64)
    slack = systematic_counts(truths, 5, 5) - np.bitwise_count(reductions(truths, 5, 5))
    return Search(5, 5, truths, slack.tolist())


def size_row(m: int, n: int, unconstrained: bool) -> dict:
    """Systematic's total, the least never-worse total and optionally the optimum, all m×n biorders."""
    start = time.perf_counter()
    truths = all_biorders(m, n)
    budget = systematic_counts(truths, m, n)
    never_worse = Search(m, n, truths, (budget - np.bitwise_count(reductions(truths, m, n))).tolist())
    row = {"size": f"{m}x{n}", "biorders": len(truths), "systematic": int(budget.sum()),
           "never_worse": never_worse.least_total(), "states": never_worse.states}
    if unconstrained:
        free = Search(m, n, truths, [None] * len(truths))
        row["optimum"], row["optimum_states"] = free.least_total(), free.states
    row["seconds"] = round(time.perf_counter() - start, 1)
    return row


def cranfield_report(seconds: float) -> dict:
    """Systematic and the first never-worse policy on the Cranfield truths (also replayed,
    completed by systematic, over all 5×5 biorders); a lower bound of the least total."""
    start = time.perf_counter()
    search = cranfield_search()
    budget = systematic_counts(search.truths, 5, 5)
    search.first_policy()
    counts = policy_counts(search)
    everything = all_biorders(5, 5)
    over_all = policy_counts(search, everything) - systematic_counts(everything, 5, 5)
    found = {"total": int(counts.sum()), "mean": round(float(counts.mean()), 4), "min": int(counts.min()),
             "max": int(counts.max()), "better": int((counts < budget).sum()),
             "worse": int((counts > budget).sum()), "states": search.states,
             "all_5x5_worse": int((over_all > 0).sum()), "all_5x5_better": int((over_all < 0).sum()),
             "seconds": round(time.perf_counter() - start, 1)}
    bound_search = cranfield_search()
    start = time.perf_counter()
    bound, exact = bound_search.lower_bound_within(seconds)
    return {"truths": len(search.truths), "systematic": {"total": int(budget.sum()),
            "mean": round(float(budget.mean()), 4), "max": int(budget.max())},
            "never_worse_policy": found,
            "least_total": {"bound": bound, "mean": round(bound / len(search.truths), 4), "exact": exact,
                            "states": bound_search.states, "seconds": round(time.perf_counter() - start, 1)}}


def all_biorders_bound(target: int, cap: int | None = None) -> dict:
    """Least Cranfield total of a policy never worse than systematic on all 5×5 biorders
    (:class:`Relaxation`), and needing ≤ ``cap`` experiments on each Cranfield truth:
    exact if ≤ ``target``, else a lower bound > ``target`` (INFEASIBLE: no such policy)."""
    start = time.perf_counter()
    everything = all_biorders(5, 5)
    counted = np.isin(everything, cranfield_search().truths)
    budget = systematic_counts(everything, 5, 5)
    if cap is not None:
        budget = np.where(counted, np.minimum(budget, cap), budget)
    relaxation = Relaxation(5, 5, budget - np.bitwise_count(reductions(everything, 5, 5)), counted)
    total = relaxation.least_total(target)
    return {"total": total, "mean": round(total / int(counted.sum()), 4), "exact": total <= target,
            "feasible": total < INFEASIBLE, "states": relaxation.states,
            "seconds": round(time.perf_counter() - start, 1)}


def main(argv: list[str]) -> int:
    parser = ArgumentParser(prog="bench dominance", description=__doc__,
                            formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--sizes", default="2x3,3x2,2x4,3x3,3x4,4x3,2x5,5x2",
                        type=comma_list(size_pair, "sizes such as 4x5", allow_empty=True),
                        help="m×n sizes, all biorders each ('' skips; 4x4 takes ~20 s)")
    parser.add_argument("--unconstrained", action="store_true",
                        help="also the unconstrained optimum (3x4: ~30 s; 4x4: too long)")
    parser.add_argument("--cranfield", action="store_true", help="the Cranfield relaxation")
    parser.add_argument("--time-limit", type=finite_float(0, 1e6, low_open=True), default=60, metavar="S",
                        help="the search for the Cranfield lower bound (iterative deepening) gives up after "
                             "S seconds (default 60)")
    parser.add_argument("--all-biorders", action="store_true",
                        help="Cranfield total of policies never worse on all 5x5 biorders (long)")
    parser.add_argument("--target", type=finite_float(0, 1000, low_open=True), default=18.8,
                        help="mean to decide (default 18.8)")
    parser.add_argument("--cap", type=int_in(0, 10**6),
                        help="with --all-biorders: at most CAP experiments per Cranfield truth")
    args = parser.parse_args(argv)
    sizes = args.sizes
    print(f"{'size':>5} {'biorders':>8} {'systematic':>10} {'never worse':>11} {'optimum':>8} "
          f"{'states':>8} {'s':>6}")
    for m, n in sizes:
        row = size_row(m, n, args.unconstrained)
        print(f"{row['size']:>5} {row['biorders']:>8} {row['systematic']:>10} {row['never_worse']:>11} "
              f"{row.get('optimum', '-'):>8} {row['states']:>8} {row['seconds']:>6}", flush=True)
    if args.cranfield:
        report = cranfield_report(args.time_limit)
        system, found, least = report["systematic"], report["never_worse_policy"], report["least_total"]
        print(f"\nCranfield, {report['truths']} distinct truths (each 16 of the 14400 relabelings):")
        print(f"  systematic: total {system['total']}, mean {system['mean']}, max {system['max']}")
        print(f"  a policy never worse than systematic on every truth: total {found['total']}, "
              f"mean {found['mean']}, min {found['min']}, max {found['max']}, better on {found['better']}, "
              f"worse on {found['worse']} ({found['states']} states, {found['seconds']} s)")
        print(f"    completed by systematic, over all 329462 5x5 biorders: worse than systematic on "
              f"{found['all_5x5_worse']}, better on {found['all_5x5_better']}")
        kind = "exact" if least["exact"] else "proven lower bound"
        print(f"  least total of such policies: {kind} {least['bound']} (mean {least['mean']}; "
              f"{least['states']} states, {least['seconds']} s)")
    if args.all_biorders:
        bound = all_biorders_bound(round(args.target * 900), args.cap)
        kind = "least (relaxed)" if bound["exact"] else f"proven > {args.target}·900, lower bound"
        result = f"{kind} {bound['total']} (mean {bound['mean']}; " if bound["feasible"] else "none exists ("
        capped = f", at most {args.cap} on each Cranfield truth" if args.cap is not None else ""
        print(f"\nCranfield total of policies never worse than systematic on every 5x5 biorder{capped}: "
              f"{result}{bound['states']} states, {bound['seconds']} s)")
    return 0

