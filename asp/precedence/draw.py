"""Human-readable drawings of a must-precede relation (paper Figs. 2, 4 and 11).

The transitive reduction is drawn in black, the implied pairs of the closure in grey
(as in the paper). Parts are laid out in layers by longest path from the first parts,
so every arrow points rightwards.
"""

from __future__ import annotations

from pathlib import Path

import networkx as nx

from asp.precedence.relation import Pair, Relation
from bridge.files import write_figure


def _graph(relation: Relation, reduction: list[Pair]) -> nx.DiGraph:
    graph = nx.DiGraph()
    graph.add_nodes_from(relation.parts)
    graph.add_edges_from(relation.pairs(), reduced=False)
    graph.add_edges_from(reduction, reduced=True)
    return graph


def to_dot(relation: Relation, reduction: list[Pair]) -> str:
    """Graphviz DOT text: reduction edges black, implied pairs grey and dashed."""
    lines = ["digraph must_precede {", "  rankdir=LR;", "  node [shape=box];"]
    lines += [f'  "{p}";' for p in relation.parts]
    for a, b, data in _graph(relation, reduction).edges(data=True):
        style = "" if data["reduced"] else " [color=grey, style=dashed]"
        lines.append(f'  "{a}" -> "{b}"{style};')
    lines.append("}")
    return "\n".join(lines) + "\n"


def _layered_positions(graph: nx.DiGraph, reduction: list[Pair]) -> dict[str, tuple[float, float]]:
    """x: longest path from the first parts (a part without predecessors sits just
    before its earliest successor); y: order in the layer by the mean y of the
    direct predecessors, which keeps reduction edges from crossing needlessly."""
    layer = {p: 0 for p in graph}
    for node in nx.topological_sort(graph):
        for successor in graph.successors(node):
            layer[successor] = max(layer[successor], layer[node] + 1)
    for node in graph:
        if graph.in_degree(node) == 0 and graph.out_degree(node):
            layer[node] = min(layer[s] for s in graph.successors(node)) - 1
    direct = nx.DiGraph(reduction)
    y: dict[str, float] = {}

    def mean_predecessor_y(p: str) -> float:
        above = [y[q] for q in (direct.predecessors(p) if p in direct else []) if q in y]
        return sum(above) / len(above) if above else 0.0

    for k in range(max(layer.values(), default=0) + 1):
        members = sorted((p for p in graph if layer[p] == k), key=mean_predecessor_y)
        for i, p in enumerate(members):
            y[p] = i - (len(members) - 1) / 2
    return {p: (float(layer[p]), y[p]) for p in graph}


def draw_png(relation: Relation, reduction: list[Pair], path: Path | str, title: str = "") -> None:
    """Draw the relation to a PNG file (matplotlib), layered left to right."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    graph = _graph(relation, reduction)
    position = _layered_positions(graph, reduction)
    layers = int(max(x for x, _ in position.values())) + 1
    figure, axis = plt.subplots(figsize=(2 + 1.6 * layers, 4))
    implied = [(a, b) for a, b, d in graph.edges(data=True) if not d["reduced"]]
    nx.draw_networkx_edges(graph, position, edgelist=implied, edge_color="0.8", ax=axis,
                           connectionstyle="arc3,rad=0.15")
    nx.draw_networkx_edges(graph, position, edgelist=reduction, edge_color="black", ax=axis, width=1.5)
    nx.draw_networkx_nodes(graph, position, node_color="white", edgecolors="black", node_size=700, ax=axis)
    nx.draw_networkx_labels(graph, position, ax=axis, font_size=9)
    from matplotlib.lines import Line2D

    axis.legend(handles=[Line2D([], [], color="black", linewidth=1.5, label="direct (transitive reduction)"),
                         Line2D([], [], color="0.8", label="implied (transitive closure)")],
                loc="lower right", fontsize=8, frameon=False)
    axis.set_title(title)
    axis.set_axis_off()
    write_figure(path, figure, dpi=120)
