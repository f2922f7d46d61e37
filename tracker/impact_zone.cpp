#include "tracker/impact_zone.h"

#include <Eigen/Dense>
#include <Eigen/Sparse>
#include <Eigen/SparseCholesky>

#include <algorithm>
#include <cstdint>
#include <utility>

namespace meniscus::tracker {

namespace {

/// Relative Tikhonov regularization of the impact-zone system (redundant constraints make
/// C M⁻¹ Cᵀ singular).
constexpr double ZONE_REGULARIZATION = 1e-12;
/// Active-set rounds of one impact zone's quadratic program (each one factorization); when they
/// end with a row still violated, projected Gauss–Seidel takes over (ZoneSolver::solve).
constexpr int MAX_ACTIVE_SET_ROUNDS = 8;
/// A row is met when it misses its target by at most this fraction of the target.
constexpr double ACTIVE_SET_TOLERANCE = 1e-3;
/// Projected Gauss–Seidel sweeps of one impact zone at most; the detect/solve loop around it
/// continues from wherever they leave the zone.
constexpr int PGS_MAX_SWEEPS = 1000;

class ZoneSolver {
public:
    ZoneSolver(const std::vector<double>& inv_mass, int max_entries)
        : m_inv_mass(inv_mass), m_max_entries(max_entries) {}

    /// One zone: the inelastic projection as the quadratic program of Harmon et al. 2008,
    /// min ½‖Δd‖²_M subject to C(d + Δd) ≥ b — every contact separates by at least its target.
    ///
    /// First an active set: the rows in the set are equalities, Δd = M⁻¹ Cᵀ λ with
    /// (C M⁻¹ Cᵀ) λ = b − C d; a row with λ < 0 would pull its pair together and leaves the
    /// set; a row outside the set that the correction leaves violated joins it. Exact and fast
    /// when it settles, but with nearly dependent rows of different targets (a point–triangle
    /// and an edge–edge contact at one place) it can cycle: rows leave with λ < 0, the
    /// correction leaves them violated, they join again. A4 curl noise at t = 27.2 (54k
    /// triangles) left six contacts violated by 1.6e-4 m through all 64 detect/solve rounds;
    /// the rigid fallback failed too and the step was halved twice (17 s instead of 2.5 s).
    ///
    /// So when MAX_ACTIVE_SET_ROUNDS end with a row still violated, the zone goes on with
    /// projected Gauss–Seidel on the dual, min ½ λᵀAλ − λᵀ(b − C d) over λ ≥ 0 with
    /// A = C M⁻¹ Cᵀ, from the active set's last λ ≥ 0: each row in turn takes the λ ≥ 0 that
    /// meets it given the others, until every row is met (or PGS_MAX_SWEEPS). It converges for
    /// any positive semidefinite A and keeps λ bounded where equalities need huge λ of both
    /// signs; the detect/solve loop around it continues from wherever the zone was left.
    void solve(const std::vector<Contact>& constraints, const std::vector<int>& rows,
               std::vector<Vec3>& d, CollisionReport& report) const {
        const auto row = [&](int r) -> const Contact& { return constraint(constraints, rows, r); };
        const auto violation = [&](int r, const std::vector<Vec3>& dd) {
            return row(r).target - relative_normal_displacement(row(r), dd);
        };
        const int m = static_cast<int>(rows.size());
        std::vector<int> vertices;
        for (int r = 0; r < m; ++r)
            vertices.insert(vertices.end(), row(r).vertices.begin(), row(r).vertices.end());
        std::sort(vertices.begin(), vertices.end());
        const int zone_vertices =
            static_cast<int>(std::unique(vertices.begin(), vertices.end()) - vertices.begin());
        report.largest_impact_zone = std::max(report.largest_impact_zone, zone_vertices);

        std::vector<int> active;  // indices into `rows`
        double tolerance = 0.0;   // violations below this count as met
        for (int r = 0; r < m; ++r) {
            tolerance = std::max(tolerance, ACTIVE_SET_TOLERANCE * row(r).target);
            if (violation(r, d) > 0.0)
                active.push_back(r);
        }
        if (active.empty())
            return;
        std::vector<std::uint8_t> in_active(rows.size(), 0);
        std::vector<Vec3> trial;  // the last correction with every λ ≥ 0; empty: none yet
        Eigen::VectorXd trial_lambda = Eigen::VectorXd::Zero(m);  // its λ, per row
        bool settled = false;
        for (int round = 0; round < MAX_ACTIVE_SET_ROUNDS && !active.empty(); ++round) {
            Eigen::VectorXd lambda;
            if (!solve_equalities(constraints, rows, active, d, lambda, report))
                break;
            std::vector<int> kept;
            for (size_t i = 0; i < active.size(); ++i)
                if (lambda[static_cast<Eigen::Index>(i)] >= 0.0)
                    kept.push_back(active[i]);
            if (kept.size() < active.size()) {
                active = std::move(kept);
                continue;
            }
            trial = d;
            trial_lambda.setZero();
            for (size_t i = 0; i < active.size(); ++i) {
                const Contact& c = row(active[i]);
                const double li = lambda[static_cast<Eigen::Index>(i)];
                trial_lambda[active[i]] = li;
                for (int k = 0; k < 4; ++k) {
                    const auto v = static_cast<size_t>(c.vertices[k]);
                    trial[v] += (li * c.weights[k] * m_inv_mass[v]) * c.normal;
                }
            }
            std::fill(in_active.begin(), in_active.end(), 0);
            for (int r : active)
                in_active[static_cast<size_t>(r)] = 1;
            bool joined = false;
            for (int r = 0; r < m; ++r)
                if (!in_active[static_cast<size_t>(r)] && violation(r, trial) > tolerance) {
                    active.push_back(r);
                    joined = true;
                }
            if (!joined) {
                settled = true;
                break;
            }
        }
        if (settled) {
            d = std::move(trial);
            return;
        }
        if (!project_gauss_seidel(constraints, rows, tolerance, trial_lambda, d, report) &&
            !trial.empty())
            d = std::move(trial);
    }

    /// Projected Gauss–Seidel for the zone's dual (see solve) from λ = `lambda` (≥ 0, per
    /// row), then d ← d + M⁻¹ Cᵀ λ. False, leaving d alone, when the matrix is too large to
    /// assemble (CollisionOptions::max_zone_matrix_entries).
    bool project_gauss_seidel(const std::vector<Contact>& constraints, const std::vector<int>& rows,
                              double tolerance, Eigen::VectorXd lambda, std::vector<Vec3>& d,
                              CollisionReport& report) const {
        const int m = static_cast<int>(rows.size());
        Eigen::SparseMatrix<double> A;
        if (!assemble_zone_matrix(constraints, rows, A, report))
            return false;
        Eigen::VectorXd miss(m);  // b − C d − A λ: how far each row is from its target
        for (int r = 0; r < m; ++r) {
            const Contact& c = constraint(constraints, rows, r);
            miss[r] = c.target - relative_normal_displacement(c, d);
        }
        miss -= A * lambda;
        const Eigen::VectorXd diagonal = A.diagonal();
        for (int sweep = 0; sweep < PGS_MAX_SWEEPS && miss.maxCoeff() > tolerance; ++sweep)
            for (int r = 0; r < m; ++r) {
                if (!(diagonal[r] > 0.0))
                    continue;  // every vertex of the row pinned
                const double change =
                    std::max(0.0, lambda[r] + miss[r] / diagonal[r]) - lambda[r];
                if (change == 0.0)
                    continue;
                lambda[r] += change;
                // A is symmetric: column r holds row r.
                for (Eigen::SparseMatrix<double>::InnerIterator it(A, r); it; ++it)
                    miss[it.row()] -= it.value() * change;
            }
        for (int r = 0; r < m; ++r) {
            const Contact& c = constraint(constraints, rows, r);
            for (int k = 0; k < 4; ++k) {
                const auto v = static_cast<size_t>(c.vertices[k]);
                d[v] += (lambda[r] * c.weights[k] * m_inv_mass[v]) * c.normal;
            }
        }
        return true;
    }

    /// λ of the rows `active` (indices into `rows`) held as equalities, A = C M⁻¹ Cᵀ factored
    /// by sparse LDLᵀ. False when every vertex is pinned, the factorization fails or the matrix
    /// would exceed CollisionOptions::max_zone_matrix_entries.
    bool solve_equalities(const std::vector<Contact>& constraints, const std::vector<int>& rows,
                          const std::vector<int>& active, const std::vector<Vec3>& d,
                          Eigen::VectorXd& lambda, CollisionReport& report) const {
        const int m = static_cast<int>(active.size());
        std::vector<int> active_rows(active.size());  // indices into `constraints`
        Eigen::VectorXd rhs(m);
        for (int r = 0; r < m; ++r) {
            active_rows[static_cast<size_t>(r)] =
                rows[static_cast<size_t>(active[static_cast<size_t>(r)])];
            const Contact& c = constraint(constraints, active_rows, r);
            rhs[r] = c.target - relative_normal_displacement(c, d);
        }
        Eigen::SparseMatrix<double> A;
        if (!assemble_zone_matrix(constraints, active_rows, A, report))
            return false;
        double scale = 0.0;
        for (int r = 0; r < m; ++r)
            scale = std::max(scale, A.coeff(r, r));
        if (!(scale > 0.0))
            return false;  // every vertex pinned
        for (int r = 0; r < m; ++r)
            A.coeffRef(r, r) += ZONE_REGULARIZATION * scale;
        const Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt(A);
        if (ldlt.info() != Eigen::Success)
            return false;
        lambda = ldlt.solve(rhs);
        return lambda.allFinite();
    }

    /// A = C M⁻¹ Cᵀ of the zone's rows, assembled sparse — rows r and s couple only through the
    /// vertices they share, A_rs = Σ_v ā_rv ā_sv m_v⁻¹ (n_r · n_s). False when the matrix would
    /// exceed CollisionOptions::max_zone_matrix_entries.
    bool assemble_zone_matrix(const std::vector<Contact>& constraints, const std::vector<int>& rows,
                              Eigen::SparseMatrix<double>& A, CollisionReport& report) const {
        const int m = static_cast<int>(rows.size());
        // Rows touching each vertex, with the row's weight for it.
        std::vector<std::pair<int, std::pair<int, double>>> touches;  // (vertex, (row, ā))
        touches.reserve(4 * rows.size());
        for (int r = 0; r < m; ++r) {
            const Contact& c = constraint(constraints, rows, r);
            for (int k = 0; k < 4; ++k)
                touches.push_back({c.vertices[k], {r, c.weights[k]}});
        }
        std::sort(touches.begin(), touches.end());
        size_t entry_count = 0;
        for (size_t a = 0; a < touches.size();) {
            size_t b = a;
            while (b < touches.size() && touches[b].first == touches[a].first)
                ++b;
            entry_count += (b - a) * (b - a);
            a = b;
        }
        if (entry_count > static_cast<size_t>(m_max_entries)) {
            ++report.oversized_zone_solves;
            return false;
        }
        std::vector<Eigen::Triplet<double>> entries;
        entries.reserve(entry_count);
        for (size_t a = 0; a < touches.size();) {
            size_t b = a;
            while (b < touches.size() && touches[b].first == touches[a].first)
                ++b;
            const double inv = m_inv_mass[static_cast<size_t>(touches[a].first)];
            if (inv > 0.0) {
                for (size_t i = a; i < b; ++i)
                    for (size_t j = a; j < b; ++j) {
                        const int ri = touches[i].second.first, rj = touches[j].second.first;
                        const Vec3& ni = constraint(constraints, rows, ri).normal;
                        const Vec3& nj = constraint(constraints, rows, rj).normal;
                        entries.emplace_back(
                            ri, rj,
                            touches[i].second.second * touches[j].second.second * inv * ni.dot(nj));
                    }
            }
            a = b;
        }
        A.resize(m, m);
        A.setFromTriplets(entries.begin(), entries.end());
        return true;
    }

private:
    static const Contact& constraint(const std::vector<Contact>& constraints,
                                     const std::vector<int>& rows, int r) {
        return constraints[static_cast<size_t>(rows[static_cast<size_t>(r)])];
    }

    const std::vector<double>& m_inv_mass;
    int m_max_entries;
};

}  // namespace

double relative_normal_displacement(const Contact& c, const std::vector<Vec3>& d) {
    Vec3 rel = Vec3::Zero();
    for (int k = 0; k < 4; ++k)
        rel += c.weights[k] * d[static_cast<size_t>(c.vertices[k])];
    return c.normal.dot(rel);
}

void project_impact_zone(const std::vector<Contact>& constraints, const std::vector<int>& rows,
                         const std::vector<double>& inv_mass, int max_zone_matrix_entries,
                         std::vector<Vec3>& d, CollisionReport& report) {
    ZoneSolver(inv_mass, max_zone_matrix_entries).solve(constraints, rows, d, report);
}

}  // namespace meniscus::tracker
