"""The learning session: planner and cells over Zenoh (cell processes, the Zenoh oracle,
the journal, the planner's Rerun log, viewing a run's recordings)."""
