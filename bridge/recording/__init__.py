"""Rerun recordings shared by the planner and the cells: the layout (application id,
entity roots, blueprints), reading ``.rrd`` files back, and compacting finished files."""
