#include "fluid/viscous_pressure.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>

namespace meniscus::fluid {

namespace {

constexpr std::array<std::array<int, 3>, 6> NEIGHBOURS = {
    {{-1, 0, 0}, {1, 0, 0}, {0, -1, 0}, {0, 1, 0}, {0, 0, -1}, {0, 0, 1}}};

/// κ on the face between cell (i, j, k) and its neighbour `n` (index into NEIGHBOURS).
double face_kappa(const InterfaceInput& interface, int i, int j, int k, int n) {
    const int axis = n / 2;
    const bool upper = n % 2 == 1;
    std::array<int, 3> f = {i, j, k};
    if (upper)
        ++f[axis];
    return interface.kappa(axis)(f[0], f[1], f[2]);
}

}  // namespace

void ViscousPressureOptions::validate() const {
    if (coupling != ViscousPressureCoupling::split &&
        coupling != ViscousPressureCoupling::incremental &&
        coupling != ViscousPressureCoupling::coupled)
        throw std::invalid_argument("ViscousPressureOptions.coupling: unknown scheme");
    if (preconditioner != SchurPreconditioner::poisson_solve &&
        preconditioner != SchurPreconditioner::v_cycle)
        throw std::invalid_argument("ViscousPressureOptions.preconditioner: unknown kind");
    if (max_passes < 1)
        throw std::invalid_argument("ViscousPressureOptions.max_passes must be at least 1");
    if (!(pass_tolerance > 0.0 && pass_tolerance < 1.0))
        throw std::invalid_argument("ViscousPressureOptions.pass_tolerance must be in (0, 1)");
    if (pass_margin < 0 || pass_margin > 1000)
        throw std::invalid_argument("ViscousPressureOptions.pass_margin must be in [0, 1000]");
}

std::size_t CellBox::size() const {
    std::size_t n = 1;
    for (int a = 0; a < 3; ++a)
        n *= static_cast<std::size_t>(std::max(0, cells(a)));
    return n;
}

CellBox CellBox::whole(const Array3<double>& cells) {
    CellBox box;
    box.hi = {cells.ni(), cells.nj(), cells.nk()};
    return box;
}

PassRegion pass_region(const std::vector<double>& r, const Array3<double>& phi,
                       const PhaseOptions& phases, FluidMode mode, double dt, double dx,
                       double speed, double tolerance, int margin) {
    if (r.size() != phi.size())
        throw std::invalid_argument("pass_region: r and phi differ in size");
    if (!(speed > 0.0) || !(tolerance > 0.0) || margin < 0)
        throw std::invalid_argument("pass_region: speed and tolerance must be > 0 and margin >= 0");
    const bool two_phase = mode == FluidMode::two_phase;
    const double nu_liquid = phases.mu_liquid / phases.rho_liquid;
    const double nu_gas = two_phase ? phases.mu_gas / phases.rho_gas : nu_liquid;
    const double scale = dt / (dx * dx);
    const auto share = [&](double nu) { return nu * scale / (1.0 + nu * scale); };
    // A cell needs passes when |r_c| exceeds this (the share of its most diffusive phase).
    const double limit_liquid = tolerance * speed / (share(nu_liquid) * dx);
    const double limit_gas = tolerance * speed / (share(std::max(nu_liquid, nu_gas)) * dx);
    PassRegion region;
    CellBox& box = region.box;
    box.lo = {phi.ni(), phi.nj(), phi.nk()};
    box.hi = {0, 0, 0};
    const double share_liquid = share(nu_liquid);
    const double share_gas = share(std::max(nu_liquid, nu_gas));
    for (int k = 0; k < phi.nk(); ++k)
        for (int j = 0; j < phi.nj(); ++j)
            for (int i = 0; i < phi.ni(); ++i) {
                const std::size_t c = phi.index(i, j, k);
                const double magnitude = std::abs(r[c]);
                if (!(magnitude > std::min(limit_liquid, limit_gas))) {
                    region.settled = std::max(
                        region.settled, std::max(share_liquid, share_gas) * magnitude * dx / speed);
                    continue;
                }
                double limit = limit_liquid;
                if (two_phase && nu_gas > nu_liquid) {
                    bool gas = !is_liquid(phi[c]);
                    for (int n = 0; n < 6 && !gas; ++n) {
                        const int a = i + NEIGHBOURS[n][0], b = j + NEIGHBOURS[n][1],
                                  d = k + NEIGHBOURS[n][2];
                        gas = phi.contains(a, b, d) && !is_liquid(phi(a, b, d));
                    }
                    if (gas)
                        limit = limit_gas;
                }
                if (!(magnitude > limit)) {
                    region.settled = std::max(region.settled, share_liquid * magnitude * dx / speed);
                    continue;
                }
                const std::array<int, 3> cell = {i, j, k};
                for (std::size_t a = 0; a < 3; ++a) {
                    box.lo[a] = std::min(box.lo[a], cell[a]);
                    box.hi[a] = std::max(box.hi[a], cell[a] + 1);
                }
            }
    if (box.hi[0] == 0) {
        box = CellBox{};
        return region;
    }
    const std::array<int, 3> n = {phi.ni(), phi.nj(), phi.nk()};
    for (std::size_t a = 0; a < 3; ++a) {
        box.lo[a] = std::max(0, box.lo[a] - std::min(margin, n[a]));
        box.hi[a] = std::min(n[a], box.hi[a] + std::min(margin, n[a]));
    }
    return region;
}

namespace {

/// Does a block of n[0] × n[1] × n[2] values from `lo` fit inside `whole`?
bool fits(const Array3<double>& whole, const std::array<int, 3>& lo,
          const std::array<int, 3>& n) {
    const std::array<int, 3> size = {whole.ni(), whole.nj(), whole.nk()};
    for (std::size_t a = 0; a < 3; ++a)
        if (lo[a] < 0 || n[a] < 0 || lo[a] + n[a] > size[a])
            return false;
    return true;
}

}  // namespace

Array3<double> part_at(const Array3<double>& whole, const std::array<int, 3>& lo, int ni, int nj,
                       int nk) {
    if (!fits(whole, lo, {ni, nj, nk}))
        throw std::invalid_argument("part_at: the part is not inside the array");
    Array3<double> part(ni, nj, nk, 0.0);
    for (int k = 0; k < nk; ++k)
        for (int j = 0; j < nj; ++j) {
            const double* row = whole.data() + whole.index(lo[0], lo[1] + j, lo[2] + k);
            std::copy(row, row + ni, part.data() + part.index(0, j, k));
        }
    return part;
}

void add_part_at(Array3<double>& whole, const std::array<int, 3>& lo, double alpha,
                 const Array3<double>& part) {
    if (!fits(whole, lo, {part.ni(), part.nj(), part.nk()}))
        throw std::invalid_argument("add_part_at: the part does not fit inside the array");
    for (int k = 0; k < part.nk(); ++k)
        for (int j = 0; j < part.nj(); ++j) {
            double* row = whole.data() + whole.index(lo[0], lo[1] + j, lo[2] + k);
            const double* from = part.data() + part.index(0, j, k);
            for (int i = 0; i < part.ni(); ++i)
                row[i] += alpha * from[i];
        }
}

InterfaceInput interface_in_box(const InterfaceInput& interface, const CellBox& box) {
    const Array3<double>& phi = interface.phi;
    for (int a = 0; a < 3; ++a)
        if (box.cells(a) <= 0 || box.lo[static_cast<std::size_t>(a)] < 0)
            throw std::invalid_argument("interface_in_box: the box is empty");
    if (box.hi[0] > phi.ni() || box.hi[1] > phi.nj() || box.hi[2] > phi.nk())
        throw std::invalid_argument("interface_in_box: the box is not inside the grid");
    InterfaceInput sub;
    sub.phi = part_at(phi, box.lo, box.cells(0), box.cells(1), box.cells(2));
    for (int axis = 0; axis < 3; ++axis) {
        std::array<int, 3> n = {box.cells(0), box.cells(1), box.cells(2)};
        ++n[static_cast<std::size_t>(axis)];
        sub.kappa(axis) = part_at(interface.kappa(axis), box.lo, n[0], n[1], n[2]);
    }
    return sub;
}

BoundaryOptions box_boundaries(const BoundaryOptions& whole, const CellBox& box,
                               const std::array<int, 3>& cells) {
    BoundaryOptions out = whole;
    for (int axis = 0; axis < 3; ++axis) {
        const std::size_t a = static_cast<std::size_t>(axis);
        const bool reaches[2] = {box.lo[a] == 0, box.hi[a] == cells[a]};
        for (int side = 0; side < 2; ++side) {
            if (reaches[side] && !whole.periodic(axis))
                continue;
            FaceBoundary cut;
            cut.type = BoundaryType::outflow;
            out.face(axis, side) = cut;
        }
    }
    return out;
}

std::vector<char> liquid_cells(const Array3<double>& phi) {
    std::vector<char> liquid(phi.size());
    for (std::size_t c = 0; c < phi.size(); ++c)
        liquid[c] = is_liquid(phi[c]) ? 1 : 0;
    return liquid;
}

void carry_pressure_to_new_phase(const std::vector<char>& was_liquid,
                                 const InterfaceInput& interface, const PhaseOptions& phases,
                                 FluidMode mode, Array3<double>& pressure) {
    if (was_liquid.empty())
        return;
    const Array3<double>& phi = interface.phi;
    if (was_liquid.size() != phi.size() || pressure.size() != phi.size())
        throw std::invalid_argument(
            "carry_pressure_to_new_phase: was_liquid, pressure and phi differ in size");
    const Array3<double> old = pressure;
    for (int k = 0; k < phi.nk(); ++k)
        for (int j = 0; j < phi.nj(); ++j)
            for (int i = 0; i < phi.ni(); ++i) {
                const std::size_t c = phi.index(i, j, k);
                const bool liquid = is_liquid(phi[c]);
                if (liquid == (was_liquid[c] != 0))
                    continue;
                double sum = 0.0, kappa = 0.0;
                int count = 0;
                bool crossed = false;
                for (int n = 0; n < 6; ++n) {
                    const int a = i + NEIGHBOURS[n][0], b = j + NEIGHBOURS[n][1],
                              d = k + NEIGHBOURS[n][2];
                    if (!phi.contains(a, b, d))
                        continue;
                    const std::size_t m = phi.index(a, b, d);
                    const bool neighbour_liquid = is_liquid(phi[m]);
                    if (neighbour_liquid == liquid && (was_liquid[m] != 0) == liquid) {
                        sum += old[m];
                        ++count;
                    } else if (neighbour_liquid != liquid && !crossed) {
                        kappa = face_kappa(interface, i, j, k, n);
                        crossed = true;
                    }
                }
                if (count > 0) {
                    pressure[c] = sum / count;
                } else if (mode == FluidMode::two_phase) {
                    // p_liquid − p_gas = σκ.
                    pressure[c] = old[c] + (liquid ? 1.0 : -1.0) * phases.sigma * kappa;
                } else {
                    pressure[c] = liquid ? phases.sigma * kappa : 0.0;
                }
            }
}

SolveResult apply_cahouet_chabard(const PressureSystem& system, const PressureSystemSolver& solver,
                                  SchurPreconditioner how, const InterfaceInput& interface,
                                  const PhaseOptions& phases, FluidMode mode, double dt, double dx,
                                  const std::vector<double>& r, std::vector<double>& z,
                                  const BlockContext& blocks) {
    const double scale = dx * dx / dt;
    std::vector<double> rhs(r.size(), 0.0);
    for (std::size_t c = 0; c < r.size(); ++c)
        rhs[c] = system.matrix.diag[c] > 0.0 ? scale * r[c] : 0.0;
    Array3<double> poisson;
    const SolveResult solve = how == SchurPreconditioner::v_cycle
                                  ? solver.precondition(rhs, poisson)
                                  : solver.solve(rhs, poisson);
    const double mu_gas = mode == FluidMode::two_phase ? phases.mu_gas : 0.0;
    z.assign(r.size(), 0.0);
    double sum = 0.0;
    std::size_t count = 0;
    for (std::size_t c = 0; c < r.size(); ++c) {
        if (!(system.matrix.diag[c] > 0.0))
            continue;
        const double mu = is_liquid(interface.phi[c]) ? phases.mu_liquid : mu_gas;
        z[c] = poisson[c] + 2.0 * mu * r[c];
        sum += z[c];
        ++count;
    }
    if (blocks.distributed()) {
        // The whole system's mean: over the cells each rank owns.
        const std::size_t layer = static_cast<std::size_t>(system.matrix.ni()) *
                                  static_cast<std::size_t>(system.matrix.nj());
        sum = 0.0;
        count = 0;
        for (std::size_t c = blocks.owned_cells_begin(layer); c < blocks.owned_cells_end(layer);
             ++c)
            if (system.matrix.diag[c] > 0.0) {
                sum += z[c];
                ++count;
            }
        sum = blocks.sum(sum);
        count = static_cast<std::size_t>(blocks.sum(static_cast<double>(count)));
    }
    if (system.singular && count > 0) {
        const double mean = sum / static_cast<double>(count);
        for (std::size_t c = 0; c < r.size(); ++c)
            if (system.matrix.diag[c] > 0.0)
                z[c] -= mean;
    }
    return solve;
}

std::vector<double> unknown_divergence(const MacGrid& grid, const InterfaceInput& interface,
                                       FluidMode mode) {
    const Array3<double>& phi = interface.phi;
    std::vector<double> divergence(phi.size(), 0.0);
    for (int k = 0; k < phi.nk(); ++k)
        for (int j = 0; j < phi.nj(); ++j)
            for (int i = 0; i < phi.ni(); ++i)
                if (mode == FluidMode::two_phase || is_liquid(phi(i, j, k)))
                    divergence[phi.index(i, j, k)] = grid.divergence(i, j, k);
    return divergence;
}

double max_velocity_difference(const MacGrid& a, const MacGrid& b) {
    double largest = 0.0;
    for (int axis = 0; axis < 3; ++axis) {
        const std::vector<double>& x = a.velocity(axis).storage();
        const std::vector<double>& y = b.velocity(axis).storage();
        if (x.size() != y.size())
            throw std::invalid_argument("max_velocity_difference: grids differ in size");
        for (std::size_t f = 0; f < x.size(); ++f)
            largest = std::max(largest, std::abs(x[f] - y[f]));
    }
    return largest;
}

}  // namespace meniscus::fluid
