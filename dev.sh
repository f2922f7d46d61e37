#!/usr/bin/env bash
# Meniscus developer entry point: installs what is missing, builds incrementally, then
#   ./dev.sh run [SCENE.json] [meniscus run options]   runs a scene (default: the README's), frames in out/
#   ./dev.sh test                                       runs the whole test suite through ctest
#   ./dev.sh sanitize                                   builds in build-sanitize/ with Address- and
#                                                       UndefinedBehaviorSanitizer and runs the fast
#                                                       tests there (CI runs it after `test`); the
#                                                       libraries and the program are instrumented,
#                                                       the test programs' own files have ASan only
#                                                       (tests/CMakeLists.txt)
#   ./dev.sh build                                      only sets up and builds
# Idempotent: with everything installed and built it only checks and runs.
set -euo pipefail
cd "$(dirname "$0")"

DEFAULT_SCENE=scenes/drop_merge.json
BUILD_DIR=${MENISCUS_BUILD_DIR:-build}
SANITIZE_BUILD_DIR=${MENISCUS_SANITIZE_BUILD_DIR:-build-sanitize}
# The sanitizer pass runs every test that takes under about 10 s in the Release suite: all unit
# tests of tracker, fluid, coupling and app, the command-line robustness tests (signals, checked
# writes, refused input) and 1 of the 8 fuzz shards (40 cases; shard 0, 13 s in the Release suite
# and 142 s under the sanitizers, where shard 7 took 106 s and shard 1 214 s). It leaves out what runs the same
# code for minutes (several times longer under the sanitizers): the validation suite, the shipped
# scene runs and physics checks (the periodic ones too: 58 and 45 s there), convergence studies,
# long stress runs, the render path through Blender and the resume tests that kill runs by the
# clock (together about 84 % of the suite's time); the resume tests of damaged checkpoints and
# changed scenes stay in. Of the runs under mpirun, whose ranks each carry the sanitizers' cost on
# 2 oversubscribed cores, the static drop on 2 ranks and the distributed grid's checks on 2 ranks
# stay in; the static drop on 3 ranks (most of the 199 s the 2- and 3-rank runs took there), the
# checkpoint round trip over 1-3 ranks (272 s there, 26 s in the Release suite), the grid's
# checks on 3 ranks (146 s) and the refusals of what ranks cannot run yet (63 s there; they stop
# before any solve) run in the Release suite only.
SANITIZE_EXCLUDE='QuickValidation|SceneRuns|ScenePhysics|PeriodicScenes\.RayleighPlateau|PeriodicScenes\.ColumnShorter|FlowScenes\.ShrinkingSphere|FlowScenes\.ThinSheet|FlowScenes\.CurlNoiseStretches'
SANITIZE_EXCLUDE+='|CollisionStress\.SphereCrushed|CollisionStress\.SpheresDrivenHeadOn|CollisionRegression|MeanCurvature\.JustPinched'
SANITIZE_EXCLUDE+='|AxisymmetricDumbbell\.Agrees|AxisymmetricDumbbell\.Converges|AxisymmetricDumbbell\.HandlePinches|AxisymmetricMcfReference\.SphereShrinks'
SANITIZE_EXCLUDE+='|LevelSetReference\.SphereFollows|LevelSetReference\.DumbbellPinches|Simulation\.MergedDrop|Simulation\.StaticDropSpurious'
SANITIZE_EXCLUDE+='|CcdFalsePositives\.NearDegenerate|RemeshAccuracy\.SplitsAtThinFolds|FluidViscosity\.TwoLayer|FluidViscosity\.Poiseuille'
SANITIZE_EXCLUDE+='|MovingWalls\.LidOverAClosedChannel|FluidSolver\.TaylorGreenVortexDecay|DropMerge\.TwoDrops|SurfaceTension\.StaticDropThrough|SurfaceTension\.SmoothingReduces'
SANITIZE_EXCLUDE+='|FuzzRun.*/[1-7]$|RenderPath|FluidScenes\.TimeDtCapsTheFluidStep'
SANITIZE_EXCLUDE+='|Resume\.FluidRunKilled|Resume\.GeometricFlowKilled|Resume\.OneAndTwoThreads'
SANITIZE_EXCLUDE+='|DistributedRun\.BubbleMerge|DistributedRun\.JetPinch|DistributedRun\.CheckpointsResume|DistributedRun\.StaticDropOnThreeRanks|DistributedRun\.RefusesWhatIsNot|DistributedGrid\.mpirun_3_ranks'
# Cases that start MPI in their process (an MPI singleton: the distributed grid and every hypre
# solve) sometimes end with LeakSanitizer's own tracer crashing at exit after the tests passed
# ("Tracer caught signal 11", 10 of them in one full sanitize run, none in 33 runs of them by
# ctest on an idle machine; once in CI for ImplicitTension's hypre comparison): a known
# intermittent fault of LSan's stop-the-world scan (google/sanitizers#1170), here at exit after
# MPI_Finalize has closed Open MPI's components. They run in a second ctest pass that retries a
# failed case up to twice: a leak or a failed test fails every time, so it still fails.
SANITIZE_RETRIED='RankCommunicator\.|HaloExchange\.|DistributedProjection\.|DistributedViscosity\.|DistributedFluidSolver\.'
SANITIZE_RETRIED+='|HyprePressure\.|FluidPressureBackends\.|/hypre_pfmg_pcg$|FluidViscosity\.MultigridAndHypre'
SANITIZE_RETRIED+='|ImplicitTension\.ViscousSolvePastTheCapillaryLimit'
# Any finding ends the program with exit code 86 (tests then fail); LeakSanitizer included.
export ASAN_OPTIONS=${ASAN_OPTIONS:-exitcode=86:detect_leaks=1:strict_string_checks=1}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-exitcode=86:print_stacktrace=1}
# Open MPI's own leaks at MPI_Init/MPI_Finalize (the hypre pressure solver), and only those.
export LSAN_OPTIONS=${LSAN_OPTIONS:-suppressions=$PWD/tests/lsan_suppressions.txt}
PACKAGES=(cmake ninja-build g++ ccache libeigen3-dev libtbb-dev libopenvdb-dev libboost-iostreams-dev
          nlohmann-json3-dev libgtest-dev libbenchmark-dev libgmp-dev python3-matplotlib python3-numpy
          blender python3-openvdb python3-meshio python3-pil libhypre-dev libopenmpi-dev)

install_missing() {
  local missing=()
  for p in "${PACKAGES[@]}"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
  done
  [ ${#missing[@]} -eq 0 ] && return 0
  echo "dev.sh: installing ${missing[*]}" >&2
  local sudo=()
  if [ "$(id -u)" -ne 0 ]; then
    command -v sudo >/dev/null || { echo "dev.sh: need root (or sudo) to install: ${missing[*]}" >&2; exit 2; }
    sudo=(sudo)
  fi
  "${sudo[@]}" env DEBIAN_FRONTEND=noninteractive apt-get update -qq
  "${sudo[@]}" env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
}

build() {
  if [ ! -f "$BUILD_DIR/build.ninja" ]; then
    cmake -S . -B "$BUILD_DIR" -G Ninja -DCMAKE_BUILD_TYPE=Release
  fi
  cmake --build "$BUILD_DIR" -j "$(nproc)"
}

# -O1 with line tables: quick to build, readable stack traces; benchmarks left out.
sanitize_build() {
  if [ ! -f "$SANITIZE_BUILD_DIR/build.ninja" ]; then
    cmake -S . -B "$SANITIZE_BUILD_DIR" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
      -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g1 -DNDEBUG" -DMENISCUS_SANITIZE=ON \
      -DMENISCUS_BUILD_BENCH=OFF
  fi
  cmake --build "$SANITIZE_BUILD_DIR" -j "$(nproc)"
}

# Tests write scratch files under std::filesystem::temp_directory_path() by fixed names; a
# private TMPDIR per ctest run keeps two suites on one machine (two clones or worktrees) from
# removing each other's files mid-test. Removed afterwards.
run_ctest() {
  local scratch rc=0
  scratch=$(mktemp -d "${TMPDIR:-/tmp}/meniscus_ctest.XXXXXX")
  TMPDIR=$scratch ctest --output-on-failure -j "$(nproc)" "$@" || rc=$?
  rm -rf "$scratch" 2>/dev/null || true
  return $rc
}

cmd=${1:-run}
shift || true
install_missing
# ctest -N's count of the tests a selection leaves.
count_tests() { ctest -N "$@" | sed -n 's/^Total Tests: //p'; }

if [ "$cmd" = sanitize ]; then
  sanitize_build
  cd "$SANITIZE_BUILD_DIR"
  # ctest's regular expressions take at most 9 groups in parentheses; past that (or with any
  # other error) -E matches nothing and the pass would silently run the whole suite.
  if [ "$(count_tests -E "$SANITIZE_EXCLUDE|$SANITIZE_RETRIED")" = "$(count_tests)" ]; then
    echo "dev.sh: SANITIZE_EXCLUDE leaves out no test (is it a regular expression ctest takes?)" >&2
    exit 2
  fi
  rc=0
  run_ctest --timeout 1800 -E "$SANITIZE_EXCLUDE|$SANITIZE_RETRIED" || rc=$?
  run_ctest --timeout 1800 -R "$SANITIZE_RETRIED" -E "$SANITIZE_EXCLUDE" --repeat until-pass:3 || rc=$?
  exit $rc
fi
build
case "$cmd" in
  run)
    scene=$DEFAULT_SCENE
    if [ $# -gt 0 ] && [[ "$1" != -* ]]; then scene=$1; shift; fi
    exec "$BUILD_DIR/app/meniscus" run "$scene" --out out "$@"
    ;;
  test)
    cd "$BUILD_DIR"
    run_ctest --timeout 900
    ;;
  build) ;;
  *) echo "usage: ./dev.sh [run [SCENE.json] [options] | test | sanitize | build]" >&2; exit 2 ;;
esac
