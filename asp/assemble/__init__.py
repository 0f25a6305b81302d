"""Executing a plan in a cell: the planner's side (plan sources, the step loop over Zenoh,
monitoring and re-planning from the current state)."""
