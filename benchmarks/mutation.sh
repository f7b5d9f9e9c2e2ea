#!/usr/bin/env bash
# Mutation testing (mutmut 3) of the modules users trust, each against only its relevant tests.
# Slow and outside CI. Results and the survivors' analysis: benchmarks/MUTATION.md.
# Needs the mutation extra: .venv/bin/pip install -e ".[dev,mutation]".
#
#   benchmarks/mutation.sh [module ...]     # default: the first seven modules below
#
# Modules: lip alip check lip_walk mpc stability metrics (the default), mpc_solvers, mpc_rest, bnb. Each
# runs in a scratch copy of the working tree (mutmut writes ./mutants and reads [tool.mutmut]
# from pyproject.toml), whose [tool.mutmut] only_mutate / pytest_add_cli_args_test_selection
# are replaced by the module's.
# Env: PYTHON (default .venv/bin/python of the repository), MUTMUT_JOBS (default nproc),
# MUTATION_OUT (default benchmarks/mutation-out: per-module logs and `mutmut results`).
set -euo pipefail

ROOT=$(cd "$(dirname "$0")/.." && pwd)
PYTHON=${PYTHON:-$ROOT/.venv/bin/python}
JOBS=${MUTMUT_JOBS:-$(nproc)}
OUT=${MUTATION_OUT:-$ROOT/benchmarks/mutation-out}
mkdir -p "$OUT"

# MUTANTS[name]: fnmatch patterns (space-separated) of the mutants to run (default: all of SRC)
declare -A SRC TESTS MUTANTS
SRC[lip]=src/footfall/models/lip.py
TESTS[lip]="tests/models/test_lip.py"
SRC[alip]=src/footfall/models/alip.py
TESTS[alip]="tests/models/test_alip.py tests/control/test_mpc_reference.py"
SRC[check]=src/footfall/planning/check.py
TESTS[check]="tests/planning/test_check_oracle.py tests/planning/test_check_report.py tests/planning/test_plan_file.py tests/planning/test_cache.py"
SRC[lip_walk]=src/footfall/planning/lip_walk.py
TESTS[lip_walk]="tests/planning/test_lip_walk.py"
SRC[mpc]=src/footfall/control/mpc.py
TESTS[mpc]="tests/control/test_mpc.py tests/control/test_mpc_reference.py"
SRC[stability]=src/footfall/quadruped/stability.py
TESTS[stability]="tests/quadruped/test_stability.py tests/quadruped/test_geometry.py tests/quadruped/test_planning.py"
SRC[metrics]=src/footfall/sim/reduced/closed_loop.py
TESTS[metrics]="tests/sim/reduced/test_metrics.py"
# only the metrics function: the rest of closed_loop.py is the loop, tested elsewhere
MUTANTS[metrics]="footfall.sim.reduced.closed_loop.x__result__mutmut_*"
# only the model building (dynamics, blocking, weights, condensing): the solvers alone have more
# mutants than an afternoon allows
MUTANTS[mpc]="footfall.control.mpc.xǁMPCWeightsǁmatrices__mutmut_* footfall.control.mpc.x_build_mpc__mutmut_*
    footfall.control.mpc.x__powers_and_sums__mutmut_* footfall.control.mpc.x__blocks_by_tick__mutmut_*
    footfall.control.mpc.x__condense_tick__mutmut_* footfall.control.mpc.xǁCondensedMPCǁstacked__mutmut_*"

# the MPC's solvers (the torque-disc QP's dual Newton method, the polygon QP through Clarabel,
# MPC.solve* and the fallback), against the same tests
SRC[mpc_solvers]=src/footfall/control/mpc.py
TESTS[mpc_solvers]="tests/control/test_mpc.py tests/control/test_mpc_reference.py tests/control/test_mpc_solvers.py tests/control/test_mpc_results.py"
MUTANTS[mpc_solvers]="footfall.control.mpc.x_solve_ball_qp__mutmut_* footfall.control.mpc.x__cold_start__mutmut_*
    footfall.control.mpc.x__ball_dual__mutmut_* footfall.control.mpc.x__newton_step__mutmut_*
    footfall.control.mpc.x__check_polygon__mutmut_* footfall.control.mpc.x__clarabel_in_polygon__mutmut_*
    footfall.control.mpc.xǁMPCǁ*__mutmut_*"

# the branch-and-bound search's optimality logic (incumbents, the gap, node evaluation, the
# result's status, bound and gap), against its fast tests (SCIP on tiny instances, a hand-built
# MIQCQP); the rest of search.py (the loops, the worker pool) needs the slow bnb-vs-SCIP tests
SRC[bnb]=src/footfall/solvers/bnb/search.py
TESTS[bnb]="tests/solvers/test_bnb_search.py"
MUTANTS[bnb]="footfall.solvers.bnb.search.xǁ_Searchǁoffer__mutmut_* footfall.solvers.bnb.search.xǁ_Searchǁgap_of__mutmut_*
    footfall.solvers.bnb.search.xǁ_Searchǁevaluate__mutmut_* footfall.solvers.bnb.search.xǁ_Searchǁresult__mutmut_*"

# the rest of mpc.py: weight and torque-limit checks, padding and cost of the condensed model
SRC[mpc_rest]=src/footfall/control/mpc.py
TESTS[mpc_rest]="tests/control/test_mpc.py tests/control/test_mpc_reference.py tests/control/test_mpc_solvers.py tests/control/test_mpc_results.py"
MUTANTS[mpc_rest]="footfall.control.mpc.xǁMPCWeightsǁ__post_init____mutmut_* footfall.control.mpc.x_pad_condensed__mutmut_*
    footfall.control.mpc.x__torque_limits__mutmut_* footfall.control.mpc.xǁCondensedMPCǁcost__mutmut_*
    footfall.control.mpc.x__check_int__mutmut_* footfall.control.mpc.xǁCondensedMPCǁblock_of_tick__mutmut_*
    footfall.control.mpc.xǁCondensedMPCǁn_blocks__mutmut_*"

run_one() {
    local name=$1 src=${SRC[$1]} tests=${TESTS[$1]} only=${MUTANTS[$1]:-}
    local work
    work=$(mktemp -d "${TMPDIR:-/tmp}/footfall-mutation-$name.XXXX")
    # the working tree without VCS data, caches or an earlier mutants/ directory
    tar -C "$ROOT" --exclude=.git --exclude=mutants --exclude=.venv --exclude='__pycache__' \
        --exclude=.mypy_cache --exclude=.ruff_cache --exclude=.pytest_cache \
        --exclude=benchmarks/mutation-out -cf - . | tar -C "$work" -xf -
    "$PYTHON" - "$work/pyproject.toml" "$src" $tests <<'PY'
import re, sys
path, src, tests = sys.argv[1], sys.argv[2], sys.argv[3:]
text = open(path).read()
block = (
    "[tool.mutmut]\n"
    'source_paths = ["src"]\n'
    f'only_mutate = ["{src}"]\n'
    f"pytest_add_cli_args_test_selection = {tests!r}\n".replace("'", '"')
    + 'pytest_add_cli_args = ["-q", "-p", "no:cacheprovider"]\n'
)
text, n = re.subn(r"\[tool\.mutmut\]\n(?:(?!\n\[).)*", block, text, flags=re.S)
assert n == 1, "pyproject.toml has no [tool.mutmut] section"
open(path, "w").write(text)
PY
    echo "== $name: $src${only:+ ($only)} against $tests (scratch $work)"
    local t0 t1
    t0=$(date +%s)
    (cd "$work" && MPLBACKEND=Agg OPENBLAS_NUM_THREADS=1 NUMBA_DISABLE_JIT=${NUMBA_DISABLE_JIT:-0} \
        "$PYTHON" -m mutmut run --max-children "$JOBS" $only) >"$OUT/$name.log" 2>&1 || true
    t1=$(date +%s)
    local keep='.'
    # the fnmatch patterns as regular expressions ("." literal, "*" any text): a "*" inside a
    # pattern (xǁMPCǁ*__mutmut_*) must match method names, not repeat the character before it
    [ -n "$only" ] && keep=$(printf '%s\n' $only | sed 's/\./\\./g; s/\*/.*/g' | paste -sd'|')
    (cd "$work" && "$PYTHON" -m mutmut results --all true) 2>&1 \
        | grep -E "^ *($keep)" >"$OUT/$name.results" || true
    echo "wall time: $((t1 - t0)) s" | tee -a "$OUT/$name.log"
    # per-status counts from `mutmut results` (lines "<mutant>: <status>")
    awk -F': ' 'NF == 2 {n[$2]++; t++} END {for (s in n) printf "%s %d  ", s, n[s];
        printf "total %d  score %.1f%%\n", t, t ? 100 * n["killed"] / t : 0}' "$OUT/$name.results" \
        | tee -a "$OUT/$name.log"
    echo "scratch copy kept for 'mutmut show <mutant>': $work"
}

for name in "${@:-lip alip check lip_walk mpc stability metrics}"; do
    for n in $name; do run_one "$n"; done
done
