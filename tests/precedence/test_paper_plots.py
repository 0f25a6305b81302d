"""The plots people compare with the paper carry what is needed to read them: the
precedence graph's legend, Figs. 12/13's titles, trial counts and one y scale, Fig. 19's title."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest
from matplotlib.figure import Figure

from asp.precedence.draw import draw_png
from asp.precedence.evaluate import evaluate, plot
from asp.precedence.relation import reduction, true_relation
from asp.sizes.evaluate import Evaluation, plot_comparison
from bridge.assembly import load_assembly


@pytest.fixture
def figures(monkeypatch: pytest.MonkeyPatch) -> list[Figure]:
    """The figures the plot functions hand to ``write_figure`` (not written)."""
    captured: list[Figure] = []

    def capture(path: Any, figure: Figure, **options: Any) -> None:
        captured.append(figure)

    for module in ("asp.precedence.draw", "asp.precedence.evaluate",
                   "asp.sizes.evaluate"):
        monkeypatch.setattr(f"{module}.write_figure", capture)
    return captured


def test_precedence_graph_has_a_legend_for_direct_and_implied_pairs(figures: list[Figure]) -> None:
    relation = true_relation(load_assembly("cranfield"))
    draw_png(relation, reduction(relation), Path("unused.png"), title="Cranfield")
    legend = figures[0].axes[0].get_legend()
    assert [t.get_text() for t in legend.get_texts()] == ["direct (transitive reduction)",
                                                          "implied (transitive closure)"]


def test_figs_12_and_13_have_titles_trial_counts_and_one_y_scale(figures: list[Figure]) -> None:
    result = evaluate(true_relation(load_assembly("cranfield")), [3, 20], trials=50, seed=1)
    plot(result, Path("unused.png"))
    left, right = figures[0].axes
    assert left.get_title().startswith("Fig. 12") and right.get_title().startswith("Fig. 13")
    assert "50 trials per m" in left.get_title() and "50 trials per m" in right.get_title()
    assert left.get_ylim() == right.get_ylim()


def test_fig_19_is_titled_with_the_cases(figures: list[Figure]) -> None:
    plot_comparison([Evaluation("systematic", {10: 3, 12: 1}), Evaluation("heuristic", {9: 4})], "unused.png")
    assert figures[0].axes[0].get_title().startswith("Fig. 19")
    assert "4 relabelings" in figures[0].axes[0].get_title()
