"""Human-readable drawings of a must-precede relation (paper Figs. 2, 4 and 11).

The transitive reduction is drawn in black, the implied pairs of the closure in grey
(as in the paper). Parts are laid out in layers by longest path from the first parts,
so every arrow points rightwards.
"""

from __future__ import annotations

from pathlib import Path

import networkx as nx

from asp.relation import Pair, Relation


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


def draw_png(relation: Relation, reduction: list[Pair], path: Path | str, title: str = "") -> None:
    """Draw the relation to a PNG file (matplotlib), layered left to right."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    graph = _graph(relation, reduction)
    layer = {p: 0 for p in relation.parts}
    for node in nx.topological_sort(graph):
        for successor in graph.successors(node):
            layer[successor] = max(layer[successor], layer[node] + 1)
    nx.set_node_attributes(graph, layer, "layer")
    position = nx.multipartite_layout(graph, subset_key="layer")
    figure, axis = plt.subplots(figsize=(2 + 1.6 * (max(layer.values()) + 1), 4))
    implied = [(a, b) for a, b, d in graph.edges(data=True) if not d["reduced"]]
    nx.draw_networkx_edges(graph, position, edgelist=implied, edge_color="0.8", ax=axis, connectionstyle="arc3,rad=0.15")
    nx.draw_networkx_edges(graph, position, edgelist=reduction, edge_color="black", ax=axis, width=1.5)
    nx.draw_networkx_nodes(graph, position, node_color="white", edgecolors="black", node_size=700, ax=axis)
    nx.draw_networkx_labels(graph, position, ax=axis, font_size=9)
    axis.set_title(title)
    axis.set_axis_off()
    figure.tight_layout()
    figure.savefig(path, dpi=120)
    plt.close(figure)
