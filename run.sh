#!/usr/bin/env bash
# The one entry point of the project.
#   ./run.sh                 set up .venv and run the main job (Cranfield: learn, plan, assemble)
#   ./run.sh test [ARGS]     set up .venv, run the linters (ruff, mypy) and the test suite (pytest ARGS)
#   ./run.sh lint            set up .venv and run the linters only
#   ./run.sh <subcommand>    run one command of the command line (each has --help)
# Commands run in the caller's working directory, so relative paths (--out rel.lp, the
# session's default runs/ folder) are relative to it; test and lint run in the repository.
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
VENV="$ROOT/.venv"
PY="$VENV/bin/python"
STAMP="$VENV/.installed-$(sha1sum "$ROOT/pyproject.toml" | cut -c1-12)"

setup() {
    if [[ ! -x "$PY" ]]; then
        python3 -m venv "$VENV" >&2
    fi
    if [[ ! -f "$STAMP" ]]; then
        echo "run.sh: installing the project into $VENV (first run only)" >&2
        "$PY" -m pip install --quiet --upgrade pip >&2
        "$PY" -m pip install --quiet -e "$ROOT[test]" >&2
        rm -f "$VENV"/.installed-*
        touch "$STAMP"
    fi
}

lint() {
    "$VENV/bin/ruff" check --quiet asp executor bridge tests
    "$VENV/bin/mypy" --no-error-summary
}

usage() {
    cat <<'USAGE'
usage: ./run.sh [SUBCOMMAND] [ARGS...]

  (none)        Cranfield end to end: learn, plan, assemble the first plan (same as: session --assemble)
  test          run the linters and the test suite (pytest options pass through, e.g. -m "not slow")
  lint          run the linters (ruff, mypy)
  precedence    learn / count / sample / evaluate / suggest precedence constraints
  sizes         learn / evaluate which part fits which hole (active exploration)
  assign        hole assignments from learned facts
  plan          complete assembly plans from learned facts
  session       planner + cells over Zenoh: the whole learning session
  assemble      execute a plan in a simulated cell (pick, move, place; monitored, re-planned)
  view          open a session's Rerun recording
  executor      the simulated PyBullet cell (teach, trial, campaign, serve)
  bench         benchmarks: precedence | sizes | plan | executor | session

Every subcommand takes --help.
USAGE
}

[[ $# -eq 0 ]] && set -- session --assemble
cmd="$1"
shift
case "$cmd" in
    -h|--help|help) usage; exit 0 ;;
esac
setup
export PYTHONPATH="$ROOT${PYTHONPATH:+:$PYTHONPATH}"
# -P: the caller's folder is not put on sys.path (a folder named asp/ there cannot shadow ours).
case "$cmd" in
    test)      cd "$ROOT"; lint; exec "$PY" -m pytest -n 2 "$@" ;;  # two workers (xdist); -n 0: serially
    lint)      cd "$ROOT"; lint ;;
    executor)  exec "$PY" -P -m executor "$@" ;;
    bench)
        if [[ "${1:-}" == "executor" ]]; then shift; exec "$PY" -P -m executor.campaign.bench "$@"; fi
        exec "$PY" -P -m asp.cli bench "$@" ;;
    *)         exec "$PY" -P -m asp.cli "$cmd" "$@" ;;
esac
