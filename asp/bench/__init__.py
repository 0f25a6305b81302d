"""Benchmarks (``./run.sh bench TOPIC``) and the research searches behind the docs' results:
each prints its figures (medians, ratios against a peer measured in the same run)."""
