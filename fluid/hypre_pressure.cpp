#include "fluid/hypre_pressure.h"

#include <HYPRE_struct_ls.h>
#include <HYPRE_utilities.h>
#include <mpi.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <mutex>
#include <stdexcept>
#include <string>

namespace meniscus::fluid {

namespace {

/// hypre keeps process-wide state (its error flag, its memory and MPI bookkeeping) and is not
/// built thread-safe: every call into it, from set-up to destruction, holds this lock. MPI is
/// initialised with MPI_THREAD_SERIALIZED to match (any thread, one at a time).
std::mutex& hypre_lock() {
    static std::mutex lock;
    return lock;
}

/// True when a launcher started this process as one rank of a job (Open MPI's mpirun sets
/// OMPI_COMM_WORLD_SIZE, PMIx launchers PMIX_RANK, MPICH/Hydra and Slurm PMI_RANK / PMI_SIZE).
bool launched_by_mpi_launcher() {
    for (const char* name : {"OMPI_COMM_WORLD_SIZE", "PMIX_RANK", "PMI_RANK", "PMI_SIZE"})
        if (std::getenv(name) != nullptr)
            return true;
    return false;
}

void finalize_mpi_at_exit() {
    std::lock_guard<std::mutex> guard(hypre_lock());
    HYPRE_Finalize();
    int finalized = 0;
    MPI_Finalized(&finalized);
    if (!finalized)
        MPI_Finalize();
}

void check(HYPRE_Int error, const char* call) {
    if (error == 0)
        return;
    // Non-convergence is reported through SolveResult, not as an error.
    if (HYPRE_CheckError(error, HYPRE_ERROR_CONV) && (error & ~HYPRE_ERROR_CONV) == 0) {
        HYPRE_ClearAllErrors();
        return;
    }
    char description[256] = {};
    HYPRE_DescribeError(error, description);
    HYPRE_ClearAllErrors();
    throw std::runtime_error(std::string("hypre: ") + call + " failed: " + description);
}

constexpr int STENCIL_SIZE = 7;
/// Entry 0 the centre, then −x, +x, −y, +y, −z, +z.
constexpr std::array<std::array<HYPRE_Int, 3>, STENCIL_SIZE> STENCIL_OFFSETS = {{
    {0, 0, 0}, {-1, 0, 0}, {1, 0, 0}, {0, -1, 0}, {0, 1, 0}, {0, 0, -1}, {0, 0, 1}}};

}  // namespace

// MPI for a plain run (no mpirun), measured on Debian 12 with Open MPI 4.1.4, as root:
//
// - Open MPI refuses root only in its launcher (mpirun/orterun need --allow-run-as-root or
//   OMPI_ALLOW_RUN_AS_ROOT=1 + OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1). A process that calls
//   MPI_Init_thread without a launcher is a "singleton" and starts fine as root with no
//   variables set.
// - But by default the singleton forks a helper daemon (`orted --hnp`), in case it later calls
//   MPI_Comm_spawn: a second process per run, sockets, ~0.3 s, and where the parent is killed or
//   PID 1 does not reap (containers) a zombie orted is left behind (seen here). We never spawn, so
//   a singleton is made *isolated* (OMPI_MCA_ess_singleton_isolated=1): no daemon.
// - One process only talks to itself: the point-to-point layer is pinned to ob1 over the `self`
//   transport (OMPI_MCA_pml=ob1, OMPI_MCA_btl=self). Without this Open MPI probes UCX, openib,
//   libfabric and shared memory at every start (0.28 s → 0.04 s for MPI_Init_thread here) and
//   the shared-memory transport would create a segment file.
// - Open MPI installs handlers for SIGSEGV/SIGBUS/SIGFPE/SIGABRT that print its own backtrace;
//   OMPI_MCA_opal_signal="" keeps the program's (and the sanitizers') handling of those signals.
// All are set with setenv(..., overwrite = 0), so a user's own OMPI_MCA_* settings win, and only
// when no MPI launcher started the process (under mpirun the launcher's set-up is left alone).
// MPI_Finalize runs from std::atexit, after HYPRE_Finalize; a hypre object still alive then (a
// solver in a static object destroyed after the exit handlers) would be destroyed after
// MPI_Finalize, so none should outlive main().
void ensure_mpi_initialized() {
    static std::once_flag once;
    std::call_once(once, [] {
        int initialized = 0;
        MPI_Initialized(&initialized);
        int finalized = 0;
        MPI_Finalized(&finalized);
        if (finalized)
            throw std::runtime_error("hypre pressure solver: MPI has already been finalised");
        if (!initialized) {
            if (!launched_by_mpi_launcher()) {
                setenv("OMPI_MCA_ess_singleton_isolated", "1", 0);
                setenv("OMPI_MCA_pml", "ob1", 0);
                setenv("OMPI_MCA_btl", "self", 0);
                setenv("OMPI_MCA_opal_signal", "", 0);
            }
            int provided = 0;
            if (MPI_Init_thread(nullptr, nullptr, MPI_THREAD_SERIALIZED, &provided) !=
                MPI_SUCCESS)
                throw std::runtime_error("hypre pressure solver: MPI_Init_thread failed");
            if (provided < MPI_THREAD_SERIALIZED)
                throw std::runtime_error(
                    "hypre pressure solver: MPI does not provide MPI_THREAD_SERIALIZED");
        }
        {
            std::lock_guard<std::mutex> guard(hypre_lock());
            check(HYPRE_Init(), "HYPRE_Init");
        }
        // Finalise only what we initialised: an MPI someone else started is theirs to end, but
        // hypre's own state is ours either way.
        if (!initialized)
            std::atexit(finalize_mpi_at_exit);
        else
            std::atexit([] {
                std::lock_guard<std::mutex> guard(hypre_lock());
                HYPRE_Finalize();
            });
    });
}

struct HyprePressureSolver::State {
    int ni = 0, nj = 0, nk = 0;
    bool singular = false;
    std::vector<char> active;  ///< per cell: diagonal > 0
    HYPRE_StructGrid grid = nullptr;
    HYPRE_StructStencil stencil = nullptr;
    HYPRE_StructMatrix matrix = nullptr;
    HYPRE_StructVector b = nullptr;
    HYPRE_StructVector x = nullptr;
    HYPRE_StructSolver pcg = nullptr;
    HYPRE_StructSolver pfmg = nullptr;
    std::array<HYPRE_Int, 3> lower = {0, 0, 0};
    std::array<HYPRE_Int, 3> upper = {0, 0, 0};

    ~State() {
        // Destruction never throws; errors here are cleared.
        if (pcg != nullptr)
            HYPRE_StructPCGDestroy(pcg);
        if (pfmg != nullptr)
            HYPRE_StructPFMGDestroy(pfmg);
        if (x != nullptr)
            HYPRE_StructVectorDestroy(x);
        if (b != nullptr)
            HYPRE_StructVectorDestroy(b);
        if (matrix != nullptr)
            HYPRE_StructMatrixDestroy(matrix);
        if (stencil != nullptr)
            HYPRE_StructStencilDestroy(stencil);
        if (grid != nullptr)
            HYPRE_StructGridDestroy(grid);
        HYPRE_ClearAllErrors();
    }

    /// Copies `values` (our layout, inactive entries zeroed) into the hypre vector `v`.
    void set_vector(HYPRE_StructVector v, const std::vector<double>& values) {
        std::vector<double> copy(values.size());
        for (std::size_t c = 0; c < values.size(); ++c)
            copy[c] = active[c] ? values[c] : 0.0;
        check(HYPRE_StructVectorSetBoxValues(v, lower.data(), upper.data(), copy.data()),
              "HYPRE_StructVectorSetBoxValues");
        check(HYPRE_StructVectorAssemble(v), "HYPRE_StructVectorAssemble");
    }
    void get_vector(HYPRE_StructVector v, std::vector<double>& values) const {
        values.assign(active.size(), 0.0);
        check(HYPRE_StructVectorGetBoxValues(v, const_cast<HYPRE_Int*>(lower.data()),
                                             const_cast<HYPRE_Int*>(upper.data()), values.data()),
              "HYPRE_StructVectorGetBoxValues");
        for (std::size_t c = 0; c < values.size(); ++c)
            if (!active[c])
                values[c] = 0.0;
    }
};

HyprePressureSolver::HyprePressureSolver(const PoissonMatrix& a, bool singular)
    : m_state(std::make_unique<State>()) {
    if (a.size() == 0)
        throw std::invalid_argument("HyprePressureSolver: empty matrix");
    ensure_mpi_initialized();
    std::lock_guard<std::mutex> guard(hypre_lock());
    State& s = *m_state;
    s.ni = a.ni();
    s.nj = a.nj();
    s.nk = a.nk();
    s.singular = singular;
    s.upper = {s.ni - 1, s.nj - 1, s.nk - 1};
    s.active.resize(a.size());
    for (std::size_t c = 0; c < a.size(); ++c)
        s.active[c] = a.diag[c] > 0.0 ? 1 : 0;
    const std::array<int, 3> n = {s.ni, s.nj, s.nk};

    // One process: every rank (if several run this) solves the whole system on its own.
    const MPI_Comm comm = MPI_COMM_SELF;
    check(HYPRE_StructGridCreate(comm, 3, &s.grid), "HYPRE_StructGridCreate");
    check(HYPRE_StructGridSetExtents(s.grid, s.lower.data(), s.upper.data()),
          "HYPRE_StructGridSetExtents");
    // A periodic axis wraps the grid itself: the stencil entry of the last cell towards +axis
    // (index n) then reads cell 0, and that of cell 0 towards −axis reads cell n−1. Along an axis
    // of one cell PoissonMatrix has no seam coupling (the cell would neighbour itself).
    std::array<HYPRE_Int, 3> periods = {0, 0, 0};
    std::array<bool, 3> wraps = {false, false, false};
    for (std::size_t axis = 0; axis < 3; ++axis) {
        wraps[axis] = a.periodic[axis] && n[axis] > 1;
        periods[axis] = wraps[axis] ? n[axis] : 0;
    }
    check(HYPRE_StructGridSetPeriodic(s.grid, periods.data()), "HYPRE_StructGridSetPeriodic");
    check(HYPRE_StructGridAssemble(s.grid), "HYPRE_StructGridAssemble");

    check(HYPRE_StructStencilCreate(3, STENCIL_SIZE, &s.stencil), "HYPRE_StructStencilCreate");
    for (int e = 0; e < STENCIL_SIZE; ++e) {
        std::array<HYPRE_Int, 3> offset = STENCIL_OFFSETS[static_cast<std::size_t>(e)];
        check(HYPRE_StructStencilSetElement(s.stencil, e, offset.data()),
              "HYPRE_StructStencilSetElement");
    }
    check(HYPRE_StructMatrixCreate(comm, s.grid, s.stencil, &s.matrix),
          "HYPRE_StructMatrixCreate");
    check(HYPRE_StructMatrixInitialize(s.matrix), "HYPRE_StructMatrixInitialize");

    // hypre's stencil entries are the matrix coefficients themselves, as PoissonMatrix::apply()
    // uses them: y_c = diag_c x_c + Σ off(c, nb) x_nb, off ≤ 0. One z-slab at a time (7 doubles
    // per cell of the slab).
    std::array<HYPRE_Int, STENCIL_SIZE> entries{};
    for (int e = 0; e < STENCIL_SIZE; ++e)
        entries[static_cast<std::size_t>(e)] = e;
    std::vector<double> values(static_cast<std::size_t>(STENCIL_SIZE) * s.ni * s.nj);
    const auto is_active = [&](int i, int j, int k) { return a.diag(i, j, k) > 0.0; };
    for (int k = 0; k < s.nk; ++k) {
        std::size_t v = 0;
        for (int j = 0; j < s.nj; ++j)
            for (int i = 0; i < s.ni; ++i) {
                const std::array<int, 3> cell = {i, j, k};
                double* row = values.data() + v;
                v += STENCIL_SIZE;
                if (!is_active(i, j, k)) {
                    // An identity row, decoupled (its right-hand side is zero: x stays 0 there).
                    std::fill(row, row + STENCIL_SIZE, 0.0);
                    row[0] = 1.0;
                    continue;
                }
                row[0] = a.diag(i, j, k);
                for (int axis = 0; axis < 3; ++axis) {
                    const std::size_t ax = static_cast<std::size_t>(axis);
                    const Array3<double>& off = a.off(axis);
                    // −axis neighbour: the entry stored at that neighbour (or the seam's at n−1).
                    std::array<int, 3> lo = cell, hi = cell;
                    bool has_lo = true, has_hi = true;
                    if (cell[ax] > 0)
                        lo[ax] = cell[ax] - 1;
                    else if (wraps[ax])
                        lo[ax] = n[ax] - 1;
                    else
                        has_lo = false;
                    if (cell[ax] + 1 < n[ax])
                        hi[ax] = cell[ax] + 1;
                    else if (wraps[ax])
                        hi[ax] = 0;
                    else
                        has_hi = false;
                    row[1 + 2 * axis] = has_lo && is_active(lo[0], lo[1], lo[2])
                                            ? off(lo[0], lo[1], lo[2])
                                            : 0.0;
                    row[2 + 2 * axis] =
                        has_hi && is_active(hi[0], hi[1], hi[2]) ? off(i, j, k) : 0.0;
                }
            }
        std::array<HYPRE_Int, 3> slab_lower = {0, 0, k}, slab_upper = {s.ni - 1, s.nj - 1, k};
        check(HYPRE_StructMatrixSetBoxValues(s.matrix, slab_lower.data(), slab_upper.data(),
                                             STENCIL_SIZE, entries.data(), values.data()),
              "HYPRE_StructMatrixSetBoxValues");
    }
    check(HYPRE_StructMatrixAssemble(s.matrix), "HYPRE_StructMatrixAssemble");

    check(HYPRE_StructVectorCreate(comm, s.grid, &s.b), "HYPRE_StructVectorCreate");
    check(HYPRE_StructVectorInitialize(s.b), "HYPRE_StructVectorInitialize");
    check(HYPRE_StructVectorCreate(comm, s.grid, &s.x), "HYPRE_StructVectorCreate");
    check(HYPRE_StructVectorInitialize(s.x), "HYPRE_StructVectorInitialize");
    const std::vector<double> zero(a.size(), 0.0);
    s.set_vector(s.b, zero);
    s.set_vector(s.x, zero);

    // PFMG as a symmetric preconditioner: one V-cycle from a zero guess, symmetric red–black
    // Gauss–Seidel (relax type 2) with one sweep before and after, Galerkin coarse operators.
    check(HYPRE_StructPFMGCreate(comm, &s.pfmg), "HYPRE_StructPFMGCreate");
    check(HYPRE_StructPFMGSetMaxIter(s.pfmg, 1), "HYPRE_StructPFMGSetMaxIter");
    check(HYPRE_StructPFMGSetTol(s.pfmg, 0.0), "HYPRE_StructPFMGSetTol");
    check(HYPRE_StructPFMGSetZeroGuess(s.pfmg), "HYPRE_StructPFMGSetZeroGuess");
    check(HYPRE_StructPFMGSetRAPType(s.pfmg, 0), "HYPRE_StructPFMGSetRAPType");
    check(HYPRE_StructPFMGSetRelaxType(s.pfmg, 2), "HYPRE_StructPFMGSetRelaxType");
    check(HYPRE_StructPFMGSetNumPreRelax(s.pfmg, 1), "HYPRE_StructPFMGSetNumPreRelax");
    check(HYPRE_StructPFMGSetNumPostRelax(s.pfmg, 1), "HYPRE_StructPFMGSetNumPostRelax");
    check(HYPRE_StructPFMGSetSkipRelax(s.pfmg, 0), "HYPRE_StructPFMGSetSkipRelax");
    check(HYPRE_StructPFMGSetPrintLevel(s.pfmg, 0), "HYPRE_StructPFMGSetPrintLevel");
    check(HYPRE_StructPFMGSetLogging(s.pfmg, 0), "HYPRE_StructPFMGSetLogging");
    if (singular) {
        // PFMG semicoarsens one axis per level down to a single cell, where it solves by dividing
        // by the diagonal; a pure-Neumann operator's Galerkin coarsening is singular, so that
        // diagonal is round-off (exactly 0 only for constant coefficients) and the cycle returns a
        // huge constant that wrecks PCG (measured: a bubble at density ratio 1000 stalled at a
        // relative residual of 2e-6 in 13 iterations). Stopping at 2 cells per axis keeps the
        // coarsest level a smoothed one, blind to the constant (the null space) as it should be.
        int levels = 1;
        for (std::size_t axis = 0; axis < 3; ++axis)
            for (int m = n[axis]; m > 2; m = (m + 1) / 2)
                ++levels;
        check(HYPRE_StructPFMGSetMaxLevels(s.pfmg, levels), "HYPRE_StructPFMGSetMaxLevels");
    }

    check(HYPRE_StructPCGCreate(comm, &s.pcg), "HYPRE_StructPCGCreate");
    // ‖r‖₂ / ‖b‖₂ as IterativeSolverOptions (hypre's default is the preconditioned norm).
    check(HYPRE_StructPCGSetTwoNorm(s.pcg, 1), "HYPRE_StructPCGSetTwoNorm");
    check(HYPRE_StructPCGSetRelChange(s.pcg, 0), "HYPRE_StructPCGSetRelChange");
    check(HYPRE_StructPCGSetPrintLevel(s.pcg, 0), "HYPRE_StructPCGSetPrintLevel");
    check(HYPRE_StructPCGSetLogging(s.pcg, 0), "HYPRE_StructPCGSetLogging");
    check(HYPRE_StructPCGSetPrecond(s.pcg, HYPRE_StructPFMGSolve, HYPRE_StructPFMGSetup, s.pfmg),
          "HYPRE_StructPCGSetPrecond");
    check(HYPRE_StructPCGSetup(s.pcg, s.matrix, s.b, s.x), "HYPRE_StructPCGSetup");
}

HyprePressureSolver::~HyprePressureSolver() {
    std::lock_guard<std::mutex> guard(hypre_lock());
    m_state.reset();
}

SolveResult HyprePressureSolver::solve(const std::vector<double>& rhs,
                                       const IterativeSolverOptions& options,
                                       std::vector<double>& x) const {
    options.validate();
    State& s = *m_state;
    if (rhs.size() != s.active.size())
        throw std::invalid_argument("HyprePressureSolver::solve: right-hand side of " +
                                    std::to_string(rhs.size()) + " values for " +
                                    std::to_string(s.active.size()) + " cells");
    options.cancel.throw_if_requested("the hypre PCG solve");
    std::vector<double> b(rhs.size());
    std::size_t active_cells = 0;
    for (std::size_t c = 0; c < b.size(); ++c) {
        b[c] = s.active[c] ? rhs[c] : 0.0;
        active_cells += s.active[c] ? 1 : 0;
    }
    const auto remove_mean = [&](std::vector<double>& v) {
        if (active_cells == 0)
            return;
        double sum = 0.0;
        for (std::size_t c = 0; c < v.size(); ++c)
            sum += s.active[c] ? v[c] : 0.0;
        const double mean = sum / static_cast<double>(active_cells);
        for (std::size_t c = 0; c < v.size(); ++c)
            if (s.active[c])
                v[c] -= mean;
    };
    if (s.singular)
        remove_mean(b);
    double b_norm_squared = 0.0;
    for (double value : b)
        b_norm_squared += value * value;
    SolveResult result;
    if (b_norm_squared == 0.0) {
        x.assign(b.size(), 0.0);
        result.converged = true;
        return result;
    }
    {
        std::lock_guard<std::mutex> guard(hypre_lock());
        s.set_vector(s.b, b);
        s.set_vector(s.x, std::vector<double>(b.size(), 0.0));
        check(HYPRE_StructPCGSetTol(s.pcg, options.tolerance), "HYPRE_StructPCGSetTol");
        check(HYPRE_StructPCGSetMaxIter(s.pcg, options.max_iterations),
              "HYPRE_StructPCGSetMaxIter");
        check(HYPRE_StructPCGSolve(s.pcg, s.matrix, s.b, s.x), "HYPRE_StructPCGSolve");
        HYPRE_Int iterations = 0;
        double residual = 0.0;
        check(HYPRE_StructPCGGetNumIterations(s.pcg, &iterations),
              "HYPRE_StructPCGGetNumIterations");
        check(HYPRE_StructPCGGetFinalRelativeResidualNorm(s.pcg, &residual),
              "HYPRE_StructPCGGetFinalRelativeResidualNorm");
        s.get_vector(s.x, x);
        result.iterations = iterations;
        result.residual = residual;
        result.converged = std::isfinite(residual) && residual <= options.tolerance;
    }
    if (s.singular)
        remove_mean(x);
    options.cancel.throw_if_requested("the hypre PCG solve");
    return result;
}

void HyprePressureSolver::apply(const std::vector<double>& r, std::vector<double>& z) const {
    State& s = *m_state;
    if (r.size() != s.active.size())
        throw std::invalid_argument("HyprePressureSolver::apply: vector of " +
                                    std::to_string(r.size()) + " values for " +
                                    std::to_string(s.active.size()) + " cells");
    std::lock_guard<std::mutex> guard(hypre_lock());
    s.set_vector(s.b, r);
    s.set_vector(s.x, std::vector<double>(r.size(), 0.0));
    // The PFMG object was set up for this matrix by HYPRE_StructPCGSetup; zero guess, one cycle.
    check(HYPRE_StructPFMGSolve(s.pfmg, s.matrix, s.b, s.x), "HYPRE_StructPFMGSolve");
    s.get_vector(s.x, z);
}

SolveResult solve_hypre_pfmg_pcg(const PoissonMatrix& matrix, const std::vector<double>& b,
                                 const IterativeSolverOptions& options, bool singular,
                                 std::vector<double>& x) {
    return HyprePressureSolver(matrix, singular).solve(b, options, x);
}

}  // namespace meniscus::fluid
