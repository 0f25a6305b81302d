"""The test suite (``./run.sh test``); one folder per package of the project."""
