#include "fluid/hypre_struct_solver.h"

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
constexpr std::array<std::array<HYPRE_Int, 3>, STENCIL_SIZE> STENCIL_OFFSETS = {
    {{0, 0, 0}, {-1, 0, 0}, {1, 0, 0}, {0, -1, 0}, {0, 1, 0}, {0, 0, -1}, {0, 0, 1}}};

}  // namespace

// hypre keeps process-wide state (its error flag, its memory and MPI bookkeeping) and is not built
// thread-safe: every call into it, from set-up to destruction, holds mpi_lock() (hypre calls MPI).
// HYPRE_Finalize is registered with std::atexit after MPI's own handler, so it runs before
// MPI_Finalize; a hypre object still alive then (a solver in a static object destroyed after the
// exit handlers) would be destroyed after MPI_Finalize, so none should outlive main().
void ensure_hypre_initialized() {
    static std::once_flag once;
    std::call_once(once, [] {
        ensure_mpi_initialized();
        {
            std::lock_guard<std::mutex> guard(mpi_lock());
            check(HYPRE_Init(), "HYPRE_Init");
        }
        std::atexit([] {
            std::lock_guard<std::mutex> guard(mpi_lock());
            HYPRE_Finalize();
        });
    });
}

struct HypreStructSolver::State {
    int ni = 0, nj = 0;
    int local_k = 0;  ///< z-layers of the caller's vectors (the block)
    int k_begin = 0;  ///< the block's layer of the first owned layer
    int owned_k = 0;  ///< owned z-layers
    bool singular = false;
    RankCommunicator ranks = RankCommunicator::self();
    std::vector<char> active;      ///< per owned cell: diagonal > 0
    std::size_t active_cells = 0;  ///< over every rank
    HYPRE_StructGrid grid = nullptr;
    HYPRE_StructStencil stencil = nullptr;
    HYPRE_StructMatrix matrix = nullptr;
    HYPRE_StructVector b = nullptr;
    HYPRE_StructVector x = nullptr;
    HYPRE_StructSolver pcg = nullptr;
    HYPRE_StructSolver pfmg = nullptr;
    std::array<HYPRE_Int, 3> lower = {0, 0, 0};  ///< the owned box, global indices
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

    std::size_t local_size() const { return static_cast<std::size_t>(ni) * nj * local_k; }
    /// Offset of the first owned cell in the caller's (block) vectors.
    std::size_t owned_offset() const { return static_cast<std::size_t>(ni) * nj * k_begin; }

    /// Copies the owned part of `values` (the block's layout; inactive entries zeroed) into the
    /// hypre vector `v`.
    void set_vector(HYPRE_StructVector v, const std::vector<double>& values) {
        std::vector<double> copy(active.size());
        const std::size_t offset = owned_offset();
        for (std::size_t c = 0; c < copy.size(); ++c)
            copy[c] = active[c] ? values[offset + c] : 0.0;
        check(HYPRE_StructVectorSetBoxValues(v, lower.data(), upper.data(), copy.data()),
              "HYPRE_StructVectorSetBoxValues");
        check(HYPRE_StructVectorAssemble(v), "HYPRE_StructVectorAssemble");
    }
    /// The owned part of `v` into `values` (the block's layout, resized; zero elsewhere).
    void get_vector(HYPRE_StructVector v, std::vector<double>& values) const {
        std::vector<double> owned(active.size(), 0.0);
        check(HYPRE_StructVectorGetBoxValues(v, const_cast<HYPRE_Int*>(lower.data()),
                                             const_cast<HYPRE_Int*>(upper.data()), owned.data()),
              "HYPRE_StructVectorGetBoxValues");
        values.assign(local_size(), 0.0);
        const std::size_t offset = owned_offset();
        for (std::size_t c = 0; c < owned.size(); ++c)
            values[offset + c] = active[c] ? owned[c] : 0.0;
    }
    /// Subtracts the mean over the active owned cells of every rank from those of `v` (block
    /// layout).
    void remove_mean(std::vector<double>& v) const {
        if (active_cells == 0)
            return;
        const std::size_t offset = owned_offset();
        double sum = 0.0;
        for (std::size_t c = 0; c < active.size(); ++c)
            sum += active[c] ? v[offset + c] : 0.0;
        const double mean = ranks.sum(sum) / static_cast<double>(active_cells);
        for (std::size_t c = 0; c < active.size(); ++c)
            if (active[c])
                v[offset + c] -= mean;
    }
};

HypreStructSolver::HypreStructSolver(const PoissonMatrix& a, bool singular)
    : HypreStructSolver(a, singular, SlabDecomposition(std::max(a.nk(), 1)),
                        RankCommunicator::self()) {}

HypreStructSolver::HypreStructSolver(const PoissonMatrix& a, bool singular,
                                     const SlabDecomposition& decomposition,
                                     const RankCommunicator& ranks)
    : m_state(std::make_unique<State>()) {
    if (a.size() == 0)
        throw std::invalid_argument("HypreStructSolver: empty matrix");
    const int rank = ranks.rank();
    if (decomposition.ranks() != ranks.size())
        throw std::invalid_argument("HypreStructSolver: a decomposition over " +
                                    std::to_string(decomposition.ranks()) + " ranks on " +
                                    std::to_string(ranks.size()));
    if (a.nk() != decomposition.local_layers(rank))
        throw std::invalid_argument("HypreStructSolver: the matrix has " + std::to_string(a.nk()) +
                                    " z-layers, rank " + std::to_string(rank) + "'s block " +
                                    std::to_string(decomposition.local_layers(rank)));
    const bool distributed = decomposition.distributed();
    if (distributed && decomposition.ghost_layers() < 1)
        throw std::invalid_argument(
            "HypreStructSolver: a distributed system needs at least one ghost layer");
    if (distributed && a.periodic[2])
        throw std::invalid_argument(
            "HypreStructSolver: a rank's block does not wrap along z (the decomposition does)");
    ensure_hypre_initialized();
    State& s = *m_state;
    s.ni = a.ni();
    s.nj = a.nj();
    s.local_k = a.nk();
    s.k_begin = decomposition.owned_begin(rank) - decomposition.local_begin(rank);
    s.owned_k = decomposition.owned_end(rank) - decomposition.owned_begin(rank);
    s.singular = singular;
    s.ranks = ranks;
    s.lower = {0, 0, decomposition.owned_begin(rank)};
    s.upper = {s.ni - 1, s.nj - 1, decomposition.owned_end(rank) - 1};
    const std::size_t layer = static_cast<std::size_t>(s.ni) * s.nj;
    s.active.resize(layer * s.owned_k);
    std::size_t active_here = 0;
    for (std::size_t c = 0; c < s.active.size(); ++c) {
        s.active[c] = a.diag[s.owned_offset() + c] > 0.0 ? 1 : 0;
        active_here += s.active[c];
    }
    s.active_cells = static_cast<std::size_t>(ranks.sum(static_cast<double>(active_here)));
    // Every call into hypre from here on holds the lock (the sum above took it itself).
    std::lock_guard<std::mutex> guard(mpi_lock());
    // The global grid's extents (x, y as the block's; z the decomposition's).
    const std::array<int, 3> n = {s.ni, s.nj, decomposition.layers()};
    const std::array<int, 3> local_n = {s.ni, s.nj, s.local_k};

    // One process: every rank (if several run this) solves the whole system on its own.
    const MPI_Comm comm = ranks.is_world() ? MPI_COMM_WORLD : MPI_COMM_SELF;
    check(HYPRE_StructGridCreate(comm, 3, &s.grid), "HYPRE_StructGridCreate");
    check(HYPRE_StructGridSetExtents(s.grid, s.lower.data(), s.upper.data()),
          "HYPRE_StructGridSetExtents");
    // A periodic axis wraps the grid itself: the stencil entry of the last cell towards +axis
    // (index n) then reads cell 0, and that of cell 0 towards −axis reads cell n−1. Along an axis
    // of one cell PoissonMatrix has no seam coupling (the cell would neighbour itself). A
    // distributed z wraps through the ghost layers of the block instead (the block's matrix holds
    // the seam's couplings like any other).
    std::array<HYPRE_Int, 3> periods = {0, 0, 0};
    std::array<bool, 3> wraps = {false, false, false};
    for (std::size_t axis = 0; axis < 3; ++axis) {
        wraps[axis] = a.periodic[axis] && n[axis] > 1;
        const bool global_wrap =
            axis == 2 && distributed ? decomposition.periodic() && n[axis] > 1 : wraps[axis];
        periods[axis] = global_wrap ? n[axis] : 0;
    }
    check(HYPRE_StructGridSetPeriodic(s.grid, periods.data()), "HYPRE_StructGridSetPeriodic");
    check(HYPRE_StructGridAssemble(s.grid), "HYPRE_StructGridAssemble");

    check(HYPRE_StructStencilCreate(3, STENCIL_SIZE, &s.stencil), "HYPRE_StructStencilCreate");
    for (int e = 0; e < STENCIL_SIZE; ++e) {
        std::array<HYPRE_Int, 3> offset = STENCIL_OFFSETS[static_cast<std::size_t>(e)];
        check(HYPRE_StructStencilSetElement(s.stencil, e, offset.data()),
              "HYPRE_StructStencilSetElement");
    }
    check(HYPRE_StructMatrixCreate(comm, s.grid, s.stencil, &s.matrix), "HYPRE_StructMatrixCreate");
    check(HYPRE_StructMatrixInitialize(s.matrix), "HYPRE_StructMatrixInitialize");

    // hypre's stencil entries are the matrix coefficients themselves, as PoissonMatrix::apply()
    // uses them: y_c = diag_c x_c + Σ off(c, nb) x_nb, off ≤ 0. One owned z-layer at a time
    // (7 doubles per cell of the layer), read from the block's matrix, whose ghost layers give
    // the couplings to the neighbouring ranks' cells.
    std::array<HYPRE_Int, STENCIL_SIZE> entries{};
    for (int e = 0; e < STENCIL_SIZE; ++e)
        entries[static_cast<std::size_t>(e)] = e;
    std::vector<double> values(static_cast<std::size_t>(STENCIL_SIZE) * layer);
    const auto is_active = [&](int i, int j, int k) { return a.diag(i, j, k) > 0.0; };
    for (int k = s.k_begin; k < s.k_begin + s.owned_k; ++k) {
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
                        lo[ax] = local_n[ax] - 1;
                    else
                        has_lo = false;
                    if (cell[ax] + 1 < local_n[ax])
                        hi[ax] = cell[ax] + 1;
                    else if (wraps[ax])
                        hi[ax] = 0;
                    else
                        has_hi = false;
                    row[1 + 2 * axis] =
                        has_lo && is_active(lo[0], lo[1], lo[2]) ? off(lo[0], lo[1], lo[2]) : 0.0;
                    row[2 + 2 * axis] =
                        has_hi && is_active(hi[0], hi[1], hi[2]) ? off(i, j, k) : 0.0;
                }
            }
        const int global_k = s.lower[2] + (k - s.k_begin);
        std::array<HYPRE_Int, 3> slab_lower = {0, 0, global_k},
                                 slab_upper = {s.ni - 1, s.nj - 1, global_k};
        check(HYPRE_StructMatrixSetBoxValues(s.matrix, slab_lower.data(), slab_upper.data(),
                                             STENCIL_SIZE, entries.data(), values.data()),
              "HYPRE_StructMatrixSetBoxValues");
    }
    check(HYPRE_StructMatrixAssemble(s.matrix), "HYPRE_StructMatrixAssemble");

    check(HYPRE_StructVectorCreate(comm, s.grid, &s.b), "HYPRE_StructVectorCreate");
    check(HYPRE_StructVectorInitialize(s.b), "HYPRE_StructVectorInitialize");
    check(HYPRE_StructVectorCreate(comm, s.grid, &s.x), "HYPRE_StructVectorCreate");
    check(HYPRE_StructVectorInitialize(s.x), "HYPRE_StructVectorInitialize");
    const std::vector<double> zero(s.local_size(), 0.0);
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

HypreStructSolver::~HypreStructSolver() {
    std::lock_guard<std::mutex> guard(mpi_lock());
    m_state.reset();
}

SolveResult HypreStructSolver::solve(const std::vector<double>& rhs,
                                     const IterativeSolverOptions& options,
                                     std::vector<double>& x) const {
    options.validate();
    State& s = *m_state;
    if (rhs.size() != s.local_size())
        throw std::invalid_argument("HypreStructSolver::solve: right-hand side of " +
                                    std::to_string(rhs.size()) + " values for " +
                                    std::to_string(s.local_size()) + " cells");
    options.cancel.throw_if_requested("the hypre PCG solve");
    std::vector<double> b(rhs.size(), 0.0);
    const std::size_t offset = s.owned_offset();
    for (std::size_t c = 0; c < s.active.size(); ++c)
        b[offset + c] = s.active[c] ? rhs[offset + c] : 0.0;
    if (s.singular)
        s.remove_mean(b);
    double b_norm_squared = 0.0;
    for (double value : b)
        b_norm_squared += value * value;
    b_norm_squared = s.ranks.sum(b_norm_squared);
    SolveResult result;
    if (b_norm_squared == 0.0) {
        x.assign(b.size(), 0.0);
        result.converged = true;
        return result;
    }
    {
        std::lock_guard<std::mutex> guard(mpi_lock());
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
        s.remove_mean(x);
    options.cancel.throw_if_requested("the hypre PCG solve");
    return result;
}

void HypreStructSolver::apply(const std::vector<double>& r, std::vector<double>& z) const {
    State& s = *m_state;
    if (r.size() != s.local_size())
        throw std::invalid_argument("HypreStructSolver::apply: vector of " +
                                    std::to_string(r.size()) + " values for " +
                                    std::to_string(s.local_size()) + " cells");
    std::lock_guard<std::mutex> guard(mpi_lock());
    s.set_vector(s.b, r);
    s.set_vector(s.x, std::vector<double>(r.size(), 0.0));
    // The PFMG object was set up for this matrix by HYPRE_StructPCGSetup; zero guess, one cycle.
    check(HYPRE_StructPFMGSolve(s.pfmg, s.matrix, s.b, s.x), "HYPRE_StructPFMGSolve");
    s.get_vector(s.x, z);
}

void HypreStructSolver::remove_mean(std::vector<double>& v) const {
    if (v.size() != m_state->local_size())
        throw std::invalid_argument("HypreStructSolver::remove_mean: vector of " +
                                    std::to_string(v.size()) + " values for " +
                                    std::to_string(m_state->local_size()) + " cells");
    m_state->remove_mean(v);
}

SolveResult solve_hypre_pfmg_pcg(const PoissonMatrix& matrix, const std::vector<double>& b,
                                 const IterativeSolverOptions& options, bool singular,
                                 std::vector<double>& x) {
    return HypreStructSolver(matrix, singular).solve(b, options, x);
}

}  // namespace meniscus::fluid
