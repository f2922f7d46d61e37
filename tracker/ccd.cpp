#include "tracker/ccd.h"

#include "tracker/distance.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <tuple>
#include <type_traits>
#include <vector>

namespace meniscus::tracker {
namespace {

/// Unit roundoff of IEEE double.
constexpr double UNIT_ROUNDOFF = 0x1p-53;
/// Certified bound of the rounding error of one corner value of F, per unit of the axis scale
/// D (the largest magnitude of the computed relative coordinates on that axis). Derivation, with
/// u the unit roundoff and all quantities per axis: each relative coordinate at t = 0 and t = 1
/// is one rounded difference (error <= u D); a linear interpolation x0 + t (x1 - x0) of such
/// values adds <= 5 u D; the products g1 V1 and g2 V2 (g1 exact, g2 = v (1 - u) rounded for the
/// triangle) add <= 2 u D; the two subtractions add <= 2 u D and 3 u D. Total <= 26 u D + O(u^2).
constexpr double CORNER_ERROR_FACTOR = 32.0 * UNIT_ROUNDOFF;
/// Absolute allowance for gradual underflow (at most one half-spacing per rounding).
/// Rounding allowance of the hull-separation pre-filter, in units of the machine epsilon
/// times |n|₁ · max|x|: a dot product of three terms errs by at most ~3u of that, and the axis
/// itself need not be exact (any direction separates or not), so 16 is generous.
constexpr double HULL_ROUNDING_FACTOR = 16.0;
constexpr double UNDERFLOW_ALLOWANCE = 64.0 * std::numeric_limits<double>::denorm_min();
/// Parameter boxes are not split below this width, keeping every box corner an exact dyadic
/// with few bits (so 1 - u and the bisection midpoints are exact).
constexpr double MIN_PARAMETER_WIDTH = 0x1p-60;
/// Boxes reserved up front on the work stack (a typical query needs far fewer).
constexpr std::size_t INITIAL_STACK_CAPACITY = 64;
/// Rounding of a 3-term dot product of doubles: <= 3u sum |terms| (+ O(u^2)), taken as 4u.
constexpr double DOT_ERROR_FACTOR = 4.0 * UNIT_ROUNDOFF;
/// A projected direction (patch normal) shorter than this fraction of what it was projected
/// from is numerical noise and is not used.
constexpr double PATCH_DIRECTION_FRACTION = 1e-6;
/// Splitting t is favoured by this factor over u and v: a time split also shrinks the
/// bilinear (rotation) terms that couple t with u and v, which u or v splits leave spread over
/// many boxes along a valley of near-contacts (nearly parallel edges, points gliding on faces).
constexpr double TIME_SPLIT_PREFERENCE = 4.0;
constexpr int NUM_CORNERS = 8;
constexpr int NUM_PARAMETERS = 3;

/// Gap function F(t, u, v) = V0(t) - g1 V1(t) - g2 V2(t), with Vi(t) = Vi(0) + t ΔVi, g1 = u and
/// g2 = v (edge–edge) or g2 = v (1 - u) (point–triangle, collapsed square).
struct GapFunction {
    std::array<std::array<double, 3>, 3> start{};  // [vector][axis]
    std::array<std::array<double, 3>, 3> delta{};  // [vector][axis]
    bool collapsed_square = false;
    std::array<double, 3> error{};  // certified corner error per axis
    double tolerance = 0.0;         // contact tolerance (image width), length units
    bool finite = true;             // false when relative coordinates overflowed
};

struct Box {
    std::array<double, NUM_PARAMETERS> lo;  // t, u, v
    std::array<double, NUM_PARAMETERS> hi;
    int depth;
};

struct SearchResult {
    bool may_collide = false;
    bool inconclusive = false;
    int boxes = 0;
    double toi_lower = 1.0;
};

/// Builds F from the relative vectors at t = 0 and t = 1 (already canonically ordered).
GapFunction make_gap_function(const std::array<Eigen::Vector3d, 3>& at_t0,
                              const std::array<Eigen::Vector3d, 3>& at_t1, bool collapsed_square,
                              const CcdOptions& options) {
    GapFunction f;
    f.collapsed_square = collapsed_square;
    double scale = 0.0;
    for (int axis = 0; axis < 3; ++axis) {
        double axis_scale = 0.0;
        for (int i = 0; i < 3; ++i) {
            const double x0 = at_t0[i][axis];
            const double x1 = at_t1[i][axis];
            f.start[i][axis] = x0;
            f.delta[i][axis] = x1 - x0;
            axis_scale = std::max({axis_scale, std::abs(x0), std::abs(x1)});
        }
        f.error[axis] = CORNER_ERROR_FACTOR * axis_scale + UNDERFLOW_ALLOWANCE;
        scale = std::max(scale, axis_scale);
        for (int i = 0; i < 3; ++i) {
            f.finite = f.finite && std::isfinite(f.delta[i][axis]) && std::isfinite(axis_scale);
        }
    }
    f.tolerance = options.tolerance_fraction * scale;
    return f;
}

/// Corner values of F on a box; corner index bits: 4 = t high, 2 = u high, 1 = v high.
void evaluate_corners(const GapFunction& f, const Box& box,
                      std::array<std::array<double, 3>, NUM_CORNERS>& values) {
    for (int it = 0; it < 2; ++it) {
        const double t = it == 0 ? box.lo[0] : box.hi[0];
        std::array<std::array<double, 3>, 3> v{};
        for (int i = 0; i < 3; ++i) {
            for (int axis = 0; axis < 3; ++axis) {
                v[i][axis] = f.start[i][axis] + t * f.delta[i][axis];
            }
        }
        for (int iu = 0; iu < 2; ++iu) {
            const double g1 = iu == 0 ? box.lo[1] : box.hi[1];
            for (int iv = 0; iv < 2; ++iv) {
                const double vv = iv == 0 ? box.lo[2] : box.hi[2];
                const double g2 = f.collapsed_square ? vv * (1.0 - g1) : vv;
                auto& out = values[static_cast<std::size_t>(it * 4 + iu * 2 + iv)];
                for (int axis = 0; axis < 3; ++axis) {
                    out[axis] = (v[0][axis] - g1 * v[1][axis]) - g2 * v[2][axis];
                }
            }
        }
    }
}

/// Corner values of one scalar multilinear function on a box, with a certified error bound.
struct ScalarRange {
    std::array<double, NUM_CORNERS> values{};
    double error = 0.0;
    double lo = 0.0;
    double hi = 0.0;

    void update_bounds() {
        lo = hi = values[0];
        for (int c = 1; c < NUM_CORNERS; ++c) {
            lo = std::min(lo, values[c]);
            hi = std::max(hi, values[c]);
        }
    }
    /// True when the exact function keeps one strict sign on the box (convex hull property).
    /// The comparisons are false for NaN, which keeps such boxes alive (conservative).
    bool excludes_zero() const { return lo > error || hi < -error; }
    /// How deep zero lies inside the range relative to its width (small: nearly excluded).
    double zero_depth() const { return std::min(hi, -lo) / (hi - lo); }
};

/// F projected on the unit direction normal to the patch F(t_mid, ., .) at the box centre
/// (the corner average minus its components along the mean u and v tangents). For near misses
/// with parallel edges or points gliding above a face this direction keeps one sign over boxes
/// far larger than the axis tests can discard. The direction is an arbitrary fixed vector as
/// far as soundness goes: the bound covers the corner errors of F and the rounding of the
/// dot products (3 products and 2 sums: <= 3u sum |n_k F_k|, taken as 4u). Returns false when
/// the patch gives no usable direction.
bool project_on_patch_normal(const GapFunction& f,
                             const std::array<std::array<double, 3>, NUM_CORNERS>& values,
                             ScalarRange& out) {
    Eigen::Vector3d centre = Eigen::Vector3d::Zero();
    Eigen::Vector3d tangent_u = Eigen::Vector3d::Zero();
    Eigen::Vector3d tangent_v = Eigen::Vector3d::Zero();
    for (int c = 0; c < NUM_CORNERS; ++c) {
        const Eigen::Vector3d x(values[c][0], values[c][1], values[c][2]);
        centre += x;
        tangent_u += (c & 2) != 0 ? x : Eigen::Vector3d(-x);
        tangent_v += (c & 1) != 0 ? x : Eigen::Vector3d(-x);
    }
    Eigen::Vector3d n = centre;
    const double n_scale = n.norm();
    for (Eigen::Vector3d* tangent : {&tangent_u, &tangent_v}) {
        Eigen::Vector3d e = *tangent;
        if (tangent == &tangent_v && tangent_u.squaredNorm() > 0.0) {
            const Eigen::Vector3d eu = tangent_u.normalized();
            e -= e.dot(eu) * eu;
        }
        if (!(e.norm() > PATCH_DIRECTION_FRACTION * tangent->norm()) || e.squaredNorm() == 0.0) {
            continue;
        }
        e.normalize();
        n -= n.dot(e) * e;
    }
    if (!(n.norm() > PATCH_DIRECTION_FRACTION * n_scale) || !n.allFinite() ||
        n.squaredNorm() == 0.0) {
        return false;
    }
    n.normalize();
    double magnitude = 0.0;
    for (int c = 0; c < NUM_CORNERS; ++c) {
        out.values[c] = n[0] * values[c][0] + n[1] * values[c][1] + n[2] * values[c][2];
        magnitude =
            std::max(magnitude, std::abs(n[0] * values[c][0]) + std::abs(n[1] * values[c][1]) +
                                    std::abs(n[2] * values[c][2]));
    }
    out.error = std::abs(n[0]) * f.error[0] + std::abs(n[1]) * f.error[1] +
                std::abs(n[2]) * f.error[2] + DOT_ERROR_FACTOR * magnitude + UNDERFLOW_ALLOWANCE;
    out.update_bounds();
    return true;
}

/// Picks the parameter to bisect: among the tests that are not yet tolerance-small, the one
/// closest to discarding the box (zero nearest to an end of its range) guides, and the
/// parameter along which its corner values change most is split. Falls back to the largest
/// change of any coordinate of F. Returns -1 when no parameter can be split further.
int choose_split(const Box& box, const std::array<std::array<double, 3>, NUM_CORNERS>& values,
                 const std::array<ScalarRange, 4>& guides, int num_guides) {
    const ScalarRange* guide = nullptr;
    for (int g = 0; g < num_guides; ++g) {
        if (guide == nullptr || guides[g].zero_depth() < guide->zero_depth()) {
            guide = &guides[g];
        }
    }
    std::array<double, NUM_PARAMETERS> guide_change{0.0, 0.0, 0.0};
    std::array<double, NUM_PARAMETERS> any_change{0.0, 0.0, 0.0};
    for (int c = 0; c < NUM_CORNERS; ++c) {
        for (int dim = 0; dim < NUM_PARAMETERS; ++dim) {
            const int bit = 4 >> dim;
            if ((c & bit) != 0) {
                continue;
            }
            if (guide != nullptr) {
                guide_change[dim] = std::max(guide_change[dim],
                                             std::abs(guide->values[c | bit] - guide->values[c]));
            }
            for (int axis = 0; axis < 3; ++axis) {
                any_change[dim] =
                    std::max(any_change[dim], std::abs(values[c | bit][axis] - values[c][axis]));
            }
        }
    }
    auto best_of = [&](const std::array<double, NUM_PARAMETERS>& change) {
        int best_dim = -1;
        double best = 0.0;
        for (int dim = 0; dim < NUM_PARAMETERS; ++dim) {
            const bool splittable = box.hi[dim] - box.lo[dim] > MIN_PARAMETER_WIDTH;
            if (splittable && (best_dim < 0 || change[dim] > best)) {
                best = change[dim];
                best_dim = dim;
            }
        }
        return best > 0.0 ? best_dim : -1;
    };
    guide_change[0] *= TIME_SPLIT_PREFERENCE;
    const int by_guide = best_of(guide_change);
    if (by_guide >= 0) {
        return by_guide;
    }
    const int by_any = best_of(any_change);
    if (by_any >= 0) {
        return by_any;
    }
    for (int dim = 0; dim < NUM_PARAMETERS; ++dim) {
        if (box.hi[dim] - box.lo[dim] > MIN_PARAMETER_WIDTH) {
            return dim;
        }
    }
    return -1;
}

/// Inclusion-based bisection over (t, u, v) in [0, 1]^3, depth first (earlier-t child first).
/// With `earliest` false it stops at the first box that cannot be discarded and is
/// tolerance-small. With `earliest` true it keeps searching the boxes that start before the
/// best contact found so far, so that toi_lower is the start of the earliest such box (up to
/// the budget; when the budget runs out, the earliest start among the boxes left is returned,
/// which is still a lower bound).
SearchResult search(const GapFunction& f, const CcdOptions& options, bool earliest,
                    double t_begin = 0.0, double t_end = 1.0) {
    SearchResult result;
    if (!f.finite) {
        result.may_collide = true;
        result.inconclusive = true;
        result.toi_lower = t_begin;
        return result;
    }
    constexpr double NO_CONTACT = std::numeric_limits<double>::infinity();
    double best = NO_CONTACT;
    int refinement_start = 0;
    auto accept = [&](const Box& box, bool inconclusive) {
        if (!result.may_collide) {
            refinement_start = result.boxes;
        }
        result.may_collide = true;
        result.inconclusive = result.inconclusive || inconclusive;
        best = std::min(best, box.lo[0]);
        result.toi_lower = best;
    };
    std::vector<Box> stack;
    stack.reserve(INITIAL_STACK_CAPACITY);
    stack.push_back(Box{{t_begin, 0.0, 0.0}, {t_end, 1.0, 1.0}, 0});
    std::array<std::array<double, 3>, NUM_CORNERS> values{};
    while (!stack.empty()) {
        const Box box = stack.back();
        stack.pop_back();
        if (box.lo[0] >= best) {
            continue;  // cannot improve the earliest contact found
        }
        const bool budget_spent = result.boxes >= options.max_boxes;
        const bool refinement_spent =
            result.may_collide && result.boxes >= refinement_start + options.max_refinement_boxes;
        if (budget_spent || refinement_spent) {
            accept(box, budget_spent);
            for (const Box& left : stack) {
                best = std::min(best, left.lo[0]);
            }
            result.toi_lower = best;
            return result;
        }
        ++result.boxes;
        evaluate_corners(f, box, values);

        std::array<ScalarRange, 4> guides{};
        int num_guides = 0;
        bool excluded = false;
        bool within_tolerance = true;
        for (int axis = 0; axis < 3 && !excluded; ++axis) {
            ScalarRange range;
            for (int c = 0; c < NUM_CORNERS; ++c) {
                range.values[c] = values[c][axis];
            }
            range.error = f.error[axis];
            range.update_bounds();
            excluded = range.excludes_zero();
            if (range.hi - range.lo > f.tolerance) {
                within_tolerance = false;
                guides[num_guides++] = range;
            }
        }
        if (excluded) {
            continue;
        }
        if (within_tolerance) {
            accept(box, false);
            if (!earliest) {
                return result;
            }
            continue;
        }
        ScalarRange projected;
        if (project_on_patch_normal(f, values, projected)) {
            if (projected.excludes_zero()) {
                continue;
            }
            if (projected.hi - projected.lo > f.tolerance) {
                guides[num_guides++] = projected;
            }
        }
        const int split_dim = choose_split(box, values, guides, num_guides);
        if (split_dim < 0) {
            accept(box, true);  // precision limit
            if (!earliest) {
                return result;
            }
            continue;
        }
        const double mid = 0.5 * (box.lo[split_dim] + box.hi[split_dim]);
        Box low = box;
        Box high = box;
        low.hi[split_dim] = mid;
        high.lo[split_dim] = mid;
        low.depth = high.depth = box.depth + 1;
        stack.push_back(high);
        stack.push_back(low);
    }
    return result;
}

/// Lexicographic order of a trajectory (x_t0, x_t1); canonical ordering makes results
/// independent of the caller's vertex order.
bool trajectory_less(const Eigen::Vector3d& a0, const Eigen::Vector3d& a1,
                     const Eigen::Vector3d& b0, const Eigen::Vector3d& b1) {
    for (int k = 0; k < 3; ++k) {
        if (a0[k] != b0[k]) {
            return a0[k] < b0[k];
        }
    }
    for (int k = 0; k < 3; ++k) {
        if (a1[k] != b1[k]) {
            return a1[k] < b1[k];
        }
    }
    return false;
}

void require_finite(std::initializer_list<const Eigen::Vector3d*> points, const char* query) {
    // x · 0 is 0 for finite x and NaN for ±∞ and NaN: one branch for all coordinates.
    double zero = 0.0;
    for (const Eigen::Vector3d* p : points)
        zero += (*p)[0] * 0.0 + (*p)[1] * 0.0 + (*p)[2] * 0.0;
    if (zero != 0.0)
        throw std::invalid_argument(std::string(query) +
                                    ": non-finite vertex position; pass finite positions");
}

/// Sound early exit: true when some plane strictly separates the convex hulls of the two
/// swept primitives. A linearly moving primitive stays inside the convex hull of its vertex
/// positions at t = 0 and t = 1, so separated hulls can never touch. Projections are computed
/// in floating point and the separation must exceed a bound on their rounding error
/// (HULL_ROUNDING_FACTOR · u · |n|₁ · max |coordinate|), so rounding can only make this say
/// "not separated". Axes are chosen by the caller (plane normals and edge-pair normals at
/// several times); a zero axis is skipped.
template <size_t N, size_t M>
bool hulls_separated(const std::array<const Eigen::Vector3d*, N>& first,
                     const std::array<const Eigen::Vector3d*, M>& second,
                     std::initializer_list<Eigen::Vector3d> axes, double position_error = 0.0) {
    double coordinate_bound = 0.0;
    for (const Eigen::Vector3d* p : first)
        coordinate_bound = std::max(coordinate_bound, p->cwiseAbs().maxCoeff());
    for (const Eigen::Vector3d* p : second)
        coordinate_bound = std::max(coordinate_bound, p->cwiseAbs().maxCoeff());
    for (const Eigen::Vector3d& n : axes) {
        if (!n.allFinite() || n.isZero(0.0))
            continue;
        const double margin = HULL_ROUNDING_FACTOR * std::numeric_limits<double>::epsilon() *
                                  n.cwiseAbs().sum() * coordinate_bound +
                              2.0 * n.cwiseAbs().sum() * position_error + UNDERFLOW_ALLOWANCE;
        double lo1 = std::numeric_limits<double>::infinity(), hi1 = -lo1, lo2 = lo1, hi2 = -lo1;
        for (const Eigen::Vector3d* p : first) {
            const double s = n.dot(*p);
            lo1 = std::min(lo1, s);
            hi1 = std::max(hi1, s);
        }
        for (const Eigen::Vector3d* p : second) {
            const double s = n.dot(*p);
            lo2 = std::min(lo2, s);
            hi2 = std::max(hi2, s);
        }
        if (hi1 + margin < lo2 || hi2 + margin < lo1)
            return true;
    }
    return false;
}

Eigen::Vector3d lerp(const Eigen::Vector3d& x0, const Eigen::Vector3d& x1, double t) {
    return x0 + t * (x1 - x0);
}

/// Time intervals of the step cleared by hulls_separated are halved at most this many times
/// (at most 2^7 - 1 interval tests, two proximity queries each).
constexpr int MAX_TIME_SPLIT_DEPTH = 6;
/// Rounding of one interpolated coordinate x0 + t (x1 - x0), in units of the machine epsilon
/// times max |x| (about 5u; taken as 8u).
constexpr double LERP_ERROR_FACTOR = 4.0;

/// The part [begin, end] of the step that uncleared_time_range could not clear; empty when
/// begin > end.
struct TimeRange {
    double begin = 1.0;
    double end = 0.0;
    bool empty() const { return begin > end; }
};

/// Clears what it can of the step [0, 1] by separating hulls on time intervals. Near misses
/// that the parameter-box search resolves only with a huge number of boxes (a point passing
/// along a sliver triangle, nearly parallel edges a tiny distance apart for the whole step)
/// are apart on short intervals along the direction of their closest points: on [ta, tb]
/// each primitive stays in the convex hull of its positions at ta and tb, and hulls_separated
/// is sound for any axis. `axes(first, second)` gives the axes of the primitives at one time
/// (closest-point direction, face normal or edge cross product). Interpolated positions err
/// by at most LERP_ERROR_FACTOR · ε · max|x| per coordinate, which the margin covers. Interval
/// ends are dyadic, so the box search over what remains keeps exact corners.
template <std::size_t N, std::size_t M, typename Axes>
TimeRange uncleared_time_range(const std::array<const Eigen::Vector3d*, N>& first_t0,
                               const std::array<const Eigen::Vector3d*, N>& first_t1,
                               const std::array<const Eigen::Vector3d*, M>& second_t0,
                               const std::array<const Eigen::Vector3d*, M>& second_t1,
                               const Axes& axes) {
    double coordinate_bound = 0.0;
    for (const auto* group : {&first_t0, &first_t1})
        for (const Eigen::Vector3d* p : *group)
            coordinate_bound = std::max(coordinate_bound, p->cwiseAbs().maxCoeff());
    for (const auto* group : {&second_t0, &second_t1})
        for (const Eigen::Vector3d* p : *group)
            coordinate_bound = std::max(coordinate_bound, p->cwiseAbs().maxCoeff());
    const double position_error =
        LERP_ERROR_FACTOR * std::numeric_limits<double>::epsilon() * coordinate_bound;
    auto at = [](const auto& x0, const auto& x1, double t) {
        std::array<Eigen::Vector3d, std::tuple_size<std::decay_t<decltype(x0)>>::value> x;
        for (std::size_t i = 0; i < x.size(); ++i)
            x[i] = lerp(*x0[i], *x1[i], t);
        return x;
    };
    struct Interval {
        double begin, end;
        int depth;
    };
    TimeRange uncleared;
    std::vector<Interval> stack{{0.0, 1.0, 0}};
    while (!stack.empty()) {
        const Interval in = stack.back();
        stack.pop_back();
        const auto first_a = at(first_t0, first_t1, in.begin);
        const auto first_b = at(first_t0, first_t1, in.end);
        const auto second_a = at(second_t0, second_t1, in.begin);
        const auto second_b = at(second_t0, second_t1, in.end);
        std::array<const Eigen::Vector3d*, 2 * N> first{};
        std::array<const Eigen::Vector3d*, 2 * M> second{};
        for (std::size_t i = 0; i < N; ++i) {
            first[i] = &first_a[i];
            first[N + i] = &first_b[i];
        }
        for (std::size_t i = 0; i < M; ++i) {
            second[i] = &second_a[i];
            second[M + i] = &second_b[i];
        }
        const auto axes_a = axes(first_a, second_a);
        const auto axes_b = axes(first_b, second_b);
        if (hulls_separated<2 * N, 2 * M>(first, second, {axes_a[0], axes_a[1], axes_b[0], axes_b[1]},
                                          position_error))
            continue;
        if (in.depth == MAX_TIME_SPLIT_DEPTH) {
            uncleared.begin = std::min(uncleared.begin, in.begin);
            uncleared.end = std::max(uncleared.end, in.end);
            continue;
        }
        const double mid = 0.5 * (in.begin + in.end);
        stack.push_back({mid, in.end, in.depth + 1});
        stack.push_back({in.begin, mid, in.depth + 1});
    }
    return uncleared;
}

SearchResult point_triangle_search(const Eigen::Vector3d& p_t0, const Eigen::Vector3d& a_t0,
                                   const Eigen::Vector3d& b_t0, const Eigen::Vector3d& c_t0,
                                   const Eigen::Vector3d& p_t1, const Eigen::Vector3d& a_t1,
                                   const Eigen::Vector3d& b_t1, const Eigen::Vector3d& c_t1,
                                   const CcdOptions& options, bool earliest) {
    require_finite({&p_t0, &a_t0, &b_t0, &c_t0, &p_t1, &a_t1, &b_t1, &c_t1}, "point_triangle_ccd");
    std::array<const Eigen::Vector3d*, 3> v0{&a_t0, &b_t0, &c_t0};
    std::array<const Eigen::Vector3d*, 3> v1{&a_t1, &b_t1, &c_t1};
    std::array<int, 3> order{0, 1, 2};
    std::sort(order.begin(), order.end(),
              [&](int i, int j) { return trajectory_less(*v0[i], *v1[i], *v0[j], *v1[j]); });
    const Eigen::Vector3d& a0 = *v0[order[0]];
    const Eigen::Vector3d& b0 = *v0[order[1]];
    const Eigen::Vector3d& c0 = *v0[order[2]];
    const Eigen::Vector3d& a1 = *v1[order[0]];
    const Eigen::Vector3d& b1 = *v1[order[1]];
    const Eigen::Vector3d& c1 = *v1[order[2]];
    {
        const Eigen::Vector3d am = 0.5 * (a0 + a1), bm = 0.5 * (b0 + b1), cm = 0.5 * (c0 + c1);
        if (hulls_separated<2, 6>(
                {&p_t0, &p_t1}, {&a0, &b0, &c0, &a1, &b1, &c1},
                {(b0 - a0).cross(c0 - a0), (b1 - a1).cross(c1 - a1), (bm - am).cross(cm - am)})) {
            return SearchResult{};
        }
    }
    const TimeRange range = uncleared_time_range<1, 3>(
        {&p_t0}, {&p_t1}, {&a0, &b0, &c0}, {&a1, &b1, &c1},
        [](const std::array<Eigen::Vector3d, 1>& p, const std::array<Eigen::Vector3d, 3>& t) {
            return std::array<Eigen::Vector3d, 2>{
                point_triangle_proximity(p[0], t[0], t[1], t[2]).normal,
                (t[1] - t[0]).cross(t[2] - t[0])};
        });
    if (range.empty()) {
        return SearchResult{};
    }
    const GapFunction f = make_gap_function({p_t0 - a0, b0 - a0, c0 - a0},
                                            {p_t1 - a1, b1 - a1, c1 - a1}, true, options);
    return search(f, options, earliest, range.begin, range.end);
}

SearchResult edge_edge_search(const Eigen::Vector3d& ea0_t0, const Eigen::Vector3d& ea1_t0,
                              const Eigen::Vector3d& eb0_t0, const Eigen::Vector3d& eb1_t0,
                              const Eigen::Vector3d& ea0_t1, const Eigen::Vector3d& ea1_t1,
                              const Eigen::Vector3d& eb0_t1, const Eigen::Vector3d& eb1_t1,
                              const CcdOptions& options, bool earliest) {
    require_finite({&ea0_t0, &ea1_t0, &eb0_t0, &eb1_t0, &ea0_t1, &ea1_t1, &eb0_t1, &eb1_t1},
                   "edge_edge_ccd");
    struct Trajectory {
        const Eigen::Vector3d* x0;
        const Eigen::Vector3d* x1;
    };
    struct EdgeTrajectory {
        Trajectory first, second;
    };
    auto less = [](const Trajectory& a, const Trajectory& b) {
        return trajectory_less(*a.x0, *a.x1, *b.x0, *b.x1);
    };
    auto make_edge = [&](Trajectory p, Trajectory q) {
        return less(q, p) ? EdgeTrajectory{q, p} : EdgeTrajectory{p, q};
    };
    EdgeTrajectory ea = make_edge({&ea0_t0, &ea0_t1}, {&ea1_t0, &ea1_t1});
    EdgeTrajectory eb = make_edge({&eb0_t0, &eb0_t1}, {&eb1_t0, &eb1_t1});
    const bool swap_edges =
        less(eb.first, ea.first) || (!less(ea.first, eb.first) && less(eb.second, ea.second));
    if (swap_edges) {
        std::swap(ea, eb);
    }
    const Eigen::Vector3d& a0 = *ea.first.x0;
    const Eigen::Vector3d& a1 = *ea.second.x0;
    const Eigen::Vector3d& b0 = *eb.first.x0;
    const Eigen::Vector3d& b1 = *eb.second.x0;
    const Eigen::Vector3d& a0e = *ea.first.x1;
    const Eigen::Vector3d& a1e = *ea.second.x1;
    const Eigen::Vector3d& b0e = *eb.first.x1;
    const Eigen::Vector3d& b1e = *eb.second.x1;
    {
        const Eigen::Vector3d da_m = 0.5 * ((a1 - a0) + (a1e - a0e));
        const Eigen::Vector3d db_m = 0.5 * ((b1 - b0) + (b1e - b0e));
        if (hulls_separated<4, 4>(
                {&a0, &a1, &a0e, &a1e}, {&b0, &b1, &b0e, &b1e},
                {(a1 - a0).cross(b1 - b0), (a1e - a0e).cross(b1e - b0e), da_m.cross(db_m)})) {
            return SearchResult{};
        }
    }
    // F = (ea0 - eb0) - u (ea0 - ea1) - v (eb1 - eb0) = [ea0 + u (ea1 - ea0)] - [eb0 + v (eb1 -
    // eb0)]
    const TimeRange range = uncleared_time_range<2, 2>(
        {&a0, &a1}, {&a0e, &a1e}, {&b0, &b1}, {&b0e, &b1e},
        [](const std::array<Eigen::Vector3d, 2>& a, const std::array<Eigen::Vector3d, 2>& b) {
            return std::array<Eigen::Vector3d, 2>{edge_edge_proximity(a[0], a[1], b[0], b[1]).normal,
                                                  (a[1] - a[0]).cross(b[1] - b[0])};
        });
    if (range.empty()) {
        return SearchResult{};
    }
    const GapFunction f = make_gap_function({a0 - b0, a0 - a1, b1 - b0},
                                            {a0e - b0e, a0e - a1e, b1e - b0e}, false, options);
    return search(f, options, earliest, range.begin, range.end);
}

Eigen::Vector3d weighted_sum(const std::array<double, 4>& w,
                             const std::array<const Eigen::Vector3d*, 4>& x) {
    return w[0] * *x[0] + w[1] * *x[1] + w[2] * *x[2] + w[3] * *x[3];
}

/// Fills the response fields of a positive result from proximity queries at toi_lower.
template <typename Proximity>
void fill_response(CcdResult& out, const std::array<const Eigen::Vector3d*, 4>& x0,
                   const std::array<const Eigen::Vector3d*, 4>& x1, Proximity proximity) {
    std::array<Eigen::Vector3d, 4> at_toi;
    for (std::size_t i = 0; i < 4; ++i) {
        at_toi[i] = lerp(*x0[i], *x1[i], out.toi_lower);
    }
    const auto first = proximity(at_toi, Eigen::Vector3d::Zero());
    const Eigen::Vector3d separation_t0 = weighted_sum(first.weights, x0);
    const Eigen::Vector3d displacement =
        weighted_sum(first.weights, x1) - weighted_sum(first.weights, x0);
    const Eigen::Vector3d fallback =
        separation_t0.squaredNorm() > 0.0 ? separation_t0 : Eigen::Vector3d(-displacement);
    const auto final_proximity = proximity(at_toi, fallback);
    out.distance_at_toi = final_proximity.distance;
    out.weights = final_proximity.weights;
    out.normal = final_proximity.normal;
    out.relative_normal_displacement =
        out.normal.dot(weighted_sum(out.weights, x1) - weighted_sum(out.weights, x0));
}

}  // namespace

void CcdOptions::validate() const {
    if (!(tolerance_fraction >= 0.0 && tolerance_fraction < 1.0)) {
        throw std::invalid_argument(
            "CcdOptions.tolerance_fraction must be finite and in [0, 1) (fraction of the "
            "query's length scale)");
    }
    if (max_boxes < 1) {
        throw std::invalid_argument("CcdOptions.max_boxes must be at least 1");
    }
    if (max_refinement_boxes < 0) {
        throw std::invalid_argument("CcdOptions.max_refinement_boxes must be non-negative");
    }
}

bool point_triangle_ccd(const Eigen::Vector3d& p_t0, const Eigen::Vector3d& a_t0,
                        const Eigen::Vector3d& b_t0, const Eigen::Vector3d& c_t0,
                        const Eigen::Vector3d& p_t1, const Eigen::Vector3d& a_t1,
                        const Eigen::Vector3d& b_t1, const Eigen::Vector3d& c_t1) {
    return point_triangle_search(p_t0, a_t0, b_t0, c_t0, p_t1, a_t1, b_t1, c_t1, CcdOptions{},
                                 false)
        .may_collide;
}

bool edge_edge_ccd(const Eigen::Vector3d& ea0_t0, const Eigen::Vector3d& ea1_t0,
                   const Eigen::Vector3d& eb0_t0, const Eigen::Vector3d& eb1_t0,
                   const Eigen::Vector3d& ea0_t1, const Eigen::Vector3d& ea1_t1,
                   const Eigen::Vector3d& eb0_t1, const Eigen::Vector3d& eb1_t1) {
    return edge_edge_search(ea0_t0, ea1_t0, eb0_t0, eb1_t0, ea0_t1, ea1_t1, eb0_t1, eb1_t1,
                            CcdOptions{}, false)
        .may_collide;
}

CcdResult point_triangle_ccd_detailed(const Eigen::Vector3d& p_t0, const Eigen::Vector3d& a_t0,
                                      const Eigen::Vector3d& b_t0, const Eigen::Vector3d& c_t0,
                                      const Eigen::Vector3d& p_t1, const Eigen::Vector3d& a_t1,
                                      const Eigen::Vector3d& b_t1, const Eigen::Vector3d& c_t1,
                                      const CcdOptions& options) {
    options.validate();
    const SearchResult s =
        point_triangle_search(p_t0, a_t0, b_t0, c_t0, p_t1, a_t1, b_t1, c_t1, options, true);
    CcdResult out;
    out.may_collide = s.may_collide;
    out.inconclusive = s.inconclusive;
    out.boxes_checked = s.boxes;
    out.toi_lower = s.may_collide ? s.toi_lower : 1.0;
    if (s.may_collide) {
        fill_response(out, {&p_t0, &a_t0, &b_t0, &c_t0}, {&p_t1, &a_t1, &b_t1, &c_t1},
                      [](const std::array<Eigen::Vector3d, 4>& x, const Eigen::Vector3d& fb) {
                          return point_triangle_proximity(x[0], x[1], x[2], x[3], fb);
                      });
    }
    return out;
}

CcdResult edge_edge_ccd_detailed(const Eigen::Vector3d& ea0_t0, const Eigen::Vector3d& ea1_t0,
                                 const Eigen::Vector3d& eb0_t0, const Eigen::Vector3d& eb1_t0,
                                 const Eigen::Vector3d& ea0_t1, const Eigen::Vector3d& ea1_t1,
                                 const Eigen::Vector3d& eb0_t1, const Eigen::Vector3d& eb1_t1,
                                 const CcdOptions& options) {
    options.validate();
    const SearchResult s = edge_edge_search(ea0_t0, ea1_t0, eb0_t0, eb1_t0, ea0_t1, ea1_t1, eb0_t1,
                                            eb1_t1, options, true);
    CcdResult out;
    out.may_collide = s.may_collide;
    out.inconclusive = s.inconclusive;
    out.boxes_checked = s.boxes;
    out.toi_lower = s.may_collide ? s.toi_lower : 1.0;
    if (s.may_collide) {
        fill_response(out, {&ea0_t0, &ea1_t0, &eb0_t0, &eb1_t0},
                      {&ea0_t1, &ea1_t1, &eb0_t1, &eb1_t1},
                      [](const std::array<Eigen::Vector3d, 4>& x, const Eigen::Vector3d& fb) {
                          return edge_edge_proximity(x[0], x[1], x[2], x[3], fb);
                      });
    }
    return out;
}

}  // namespace meniscus::tracker
