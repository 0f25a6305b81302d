#!/usr/bin/env bash
# The repository's wrapper around the console command `assembly-constraints` (the one
# `pip install .` installs): it sets up .venv (editable, versions pinned by constraints.txt).
#   ./run.sh                 set up .venv and run the main job (Cranfield: learn, plan, assemble)
#   ./run.sh test [ARGS]     set up .venv, run the linters (ruff, mypy) and the test suite (pytest ARGS;
#                            without a selection in ARGS, then the franka_arm tests serially)
#   ./run.sh lint            set up .venv and run the linters only
#   ./run.sh <subcommand>    assembly-constraints <subcommand> (each has --help)
# Commands run in the caller's working directory, so relative paths (--out rel.lp, the
# session's default runs/ folder) are relative to it; test and lint run in the repository.
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
VENV="$ROOT/.venv"
PY="$VENV/bin/python"
STAMP="$VENV/.installed-$(cat "$ROOT/pyproject.toml" "$ROOT/setup.py" "$ROOT/constraints.txt" | sha1sum | cut -c1-12)"

setup() {
    if [[ ! -x "$PY" ]]; then
        python3 -m venv "$VENV" >&2
    fi
    if [[ ! -f "$STAMP" ]]; then
        echo "run.sh: installing the project into $VENV (first run only)" >&2
        "$PY" -m pip install --quiet --upgrade pip >&2
        # setuptools reports every editable install with a note, "Editable installation.",
        # that names no problem; it is the one message of the build kept out of the output.
        PYTHONWARNINGS="ignore:Editable installation" \
            "$PY" -m pip install --quiet -c "$ROOT/constraints.txt" -e "$ROOT[test,franka]" >&2
        rm -f "$VENV"/.installed-*
        touch "$STAMP"
    fi
}

# Whether pytest ARGS select tests themselves: a marker (-m), a keyword (-k), a path, a
# deselection, the last failures or the stepwise run.
selects_tests() {
    local arg
    for arg in "$@"; do
        case "$arg" in
            -m|-m*|-k|-k*|--deselect*|--ignore*|--lf|--last-failed|--ff|--failed-first|--sw*|--stepwise*) return 0 ;;
            -*) ;;
            *) [[ -e "${arg%%::*}" ]] && return 0 ;;
        esac
    done
    return 1
}

# The folder of the franky arm tests (the franka_arm marker), collected alone for their run:
# collecting the whole suite to select them took longer than some of them.
ARM_TESTS="tests/franka"

# The suite on two workers, then (unless ARGS select tests) the franky arm tests alone and
# serially: each runs a 1 kHz control loop beside franky-sim's, and a second worker's
# physics starves them (docs/development.md).
run_tests() {
    local status=0 arm=0
    "$PY" -m pytest -n 2 "$@" || status=$?
    if ! selects_tests "$@"; then
        echo "run.sh: the franka_arm tests, serially" >&2
        "$PY" -m pytest "$@" -n 0 -m franka_arm "$ARM_TESTS" || arm=$?
        [[ $status -ne 0 ]] || status=$arm
    fi
    return "$status"
}

lint() {
    "$VENV/bin/ruff" check --quiet
    "$VENV/bin/mypy" --no-error-summary
}

usage() {
    cat <<'USAGE'
usage: ./run.sh [SUBCOMMAND] [ARGS...]

The repository's wrapper around assembly-constraints (below); without a subcommand it
runs the main job: Cranfield end to end, learn, plan, assemble the first plan (same as
session --assemble). Two subcommands of its own:
  test          run the linters and the test suite (pytest options pass through, e.g. -m "not slow");
                without a selection (-m, -k, a path) the franka_arm tests follow, serially
  lint          run the linters (ruff, mypy)

USAGE
}

[[ $# -eq 0 ]] && set -- session --assemble
cmd="$1"
shift
case "$cmd" in
    -h|--help|help) usage; setup; exec "$PY" -P -m assembly_constraints --help ;;
esac
setup
export PYTHONPATH="$ROOT${PYTHONPATH:+:$PYTHONPATH}"
# -P: the caller's folder is not put on sys.path (a folder named asp/ there cannot shadow ours).
case "$cmd" in
    # Bytecode caches on for the tests (an environment may turn them off): pytest then
    # rewrites each test module's asserts once, not at every collection in every worker.
    test)      cd "$ROOT"; lint; unset PYTHONDONTWRITEBYTECODE; run_tests "$@" ;;  # two workers (xdist); -n 0: serially
    lint)      cd "$ROOT"; lint ;;
    *)         exec "$PY" -P -m assembly_constraints "$cmd" "$@" ;;
esac
