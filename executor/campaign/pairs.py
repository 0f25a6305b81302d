"""The part-hole pairs of the campaign and the counts per pair (paper Fig. 18).

The pairs are the fitting rows of Fig. 18, in the paper's order, then every non-fitting
pair of parts {p1, tp, p3, sh} x holes {r1, br, s1}; :class:`PairStats` holds one row of
the table.  Shared by the campaign (:mod:`executor.campaign.run`) and its figures
(:mod:`executor.campaign.plots`), which is why it is a module of its own.
"""

from __future__ import annotations

import argparse
import statistics
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

from bridge.cli_types import comma_list, part_hole_pair
from executor import ExecutorError

FIG18_FITTING_PAIRS: tuple[tuple[str, str], ...] = (
    ("p1", "r1"), ("p1", "br"), ("p1", "s1"),
    ("tp", "r1"), ("tp", "br"), ("tp", "s1"),
    ("p3", "br"), ("p3", "s1"),
    ("sh", "br"),
)
"""The rows of the paper's Fig. 18, in its order (H1 = r1, H3 = br, H4 = s1)."""
CAMPAIGN_PARTS = ("p1", "tp", "p3", "sh")
CAMPAIGN_HOLES = ("r1", "br", "s1")
PART_NAMES = {"p1": "round peg", "tp": "tight round peg", "p3": "square peg", "sh": "shaft"}
HOLE_NAMES = {"r1": "H1 small round", "br": "H3 big round", "s1": "H4 square"}


@dataclass(frozen=True)
class CampaignPair:
    """A part-hole pair of the campaign and whether the part truly fits."""

    part: str
    hole: str
    fits: bool


def campaign_pairs() -> list[CampaignPair]:
    """Fig. 18's fitting pairs (paper order), then the non-fitting ones."""
    fitting = [CampaignPair(p, h, True) for p, h in FIG18_FITTING_PAIRS]
    others = [
        CampaignPair(p, h, False)
        for p in CAMPAIGN_PARTS for h in CAMPAIGN_HOLES
        if (p, h) not in FIG18_FITTING_PAIRS
    ]
    return fitting + others


PAIRS_ARGUMENT = comma_list(part_hole_pair, "PART:HOLE pairs such as p1:r1")
"""The argparse ``type=`` of ``--pairs``: ``"p1:r1,p3:s1"`` → ``[("p1", "r1"), ("p3", "s1")]``."""


def select_pairs(spec: str | Sequence[tuple[str, str]] | None) -> list[CampaignPair]:
    """All campaign pairs, or those named in ``spec``: the parsed ``--pairs`` list
    (``[("p1", "r1"), ("p3", "r1")]``) or its text (``"p1:r1,p3:r1"``)."""
    pairs = campaign_pairs()
    if not spec:
        return pairs
    if isinstance(spec, str):
        try:
            spec = PAIRS_ARGUMENT(spec)
        except argparse.ArgumentTypeError as exc:
            raise ExecutorError(f"--pairs: {exc}") from None
    by_name = {(p.part, p.hole): p for p in pairs}
    chosen = []
    for part, hole in spec:
        if (part, hole) not in by_name:
            raise ExecutorError(
                f"--pairs: unknown pair '{part}:{hole}'; expected PART:HOLE among "
                f"{', '.join(f'{p}:{h}' for p, h in by_name)}"
            )
        chosen.append(by_name[part, hole])
    return chosen


@dataclass
class PairStats:
    """Counts over the trials of one pair (the columns of Fig. 18, plus ours)."""

    part: str
    hole: str
    fits: bool
    trials: int
    first_trial: int
    """fitting pair: reported 'fit' at the 1st attempt"""
    after_second: int
    """fitting pair: reported 'fit' within two attempts"""
    correct: int
    """'fit' for a fitting pair, 'no_fit' for a non-fitting one"""
    false_fits: int
    """non-fitting pair reported 'fit' (must stay 0)"""
    median_duration_s: float
    """median wall time of one trial [s]"""

    @property
    def correct_ratio(self) -> float:
        return self.correct / self.trials if self.trials else 0.0


def pair_stats(pair: CampaignPair, results: Sequence[dict[str, Any]]) -> PairStats:
    """Fig. 18's counts for one pair from its trial results."""
    fit = [r for r in results if r["outcome"] == "fit"]
    first = sum(1 for r in fit if r["attempts"] == 1)
    return PairStats(
        part=pair.part, hole=pair.hole, fits=pair.fits, trials=len(results),
        first_trial=first if pair.fits else 0,
        after_second=len(fit) if pair.fits else 0,
        correct=len(fit) if pair.fits else len(results) - len(fit),
        false_fits=0 if pair.fits else len(fit),
        median_duration_s=statistics.median(r["duration_s"] for r in results) if results else 0.0,
    )
