// Collision-safe remeshing of periodic meshes (issue 39): the element hash finds neighbours
// across the seam, the local safety checks see collisions across it, and improve_mesh() on a
// periodic tube and a doubly periodic sheet leaves a valid, intersection-free periodic mesh
// of the same shape, remeshing seam elements like any other.
//
// Volumes, intersections and degenerate triangles are measured here by the minimum image
// (triangle_positions), independently of mesh_measures / mesh_intersections.

#include "periodic_meshes.h"
#include "tracker/intersection.h"
#include "tracker/mesh_validate.h"
#include "tracker/remesh/collapse.h"
#include "tracker/remesh/element_hash.h"
#include "tracker/remesh/improve.h"
#include "tracker/remesh/local_safety.h"
#include "tracker/remesh/sizing.h"
#include "tracker/remesh/split.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <set>
#include <vector>

namespace meniscus::tracker {
namespace {

constexpr double PI = 3.14159265358979323846;

/// Enclosed volume by the divergence theorem with F = (x_a − c) e_a along an axis a that does
/// not wrap (exact for a surface closed in the periodic box).
double volume_along(const SurfaceMesh& mesh, int axis) {
    double v = 0.0;
    for (int ti = 0; ti < mesh.num_triangles(); ++ti) {
        if (!mesh.triangle_alive(ti))
            continue;
        const auto p = mesh.triangle_positions(ti);
        const Vec3 area = 0.5 * (p[1] - p[0]).cross(p[2] - p[0]);
        v += area[axis] * (p[0][axis] + p[1][axis] + p[2][axis]) / 3.0;
    }
    return v;
}

/// Pairs of live triangles that intersect (exact, shared-vertex aware) with the second at its
/// image nearest the first's first corner: the brute-force periodic answer for elements much
/// shorter than a period (only that image can come near).
int count_intersecting_pairs(const SurfaceMesh& mesh) {
    std::vector<int> live;
    for (int ti = 0; ti < mesh.num_triangles(); ++ti)
        if (mesh.triangle_alive(ti))
            live.push_back(ti);
    int count = 0;
    for (size_t i = 0; i < live.size(); ++i) {
        const auto a = mesh.triangle_positions(live[i]);
        Box3d box_a(a[0]);
        box_a.extend(a[1]);
        box_a.extend(a[2]);
        for (size_t j = i + 1; j < live.size(); ++j) {
            const Triangle& t = mesh.triangle(live[j]);
            // The second triangle whole (its corners at the minimum image of its first), moved
            // by whole periods towards the first; where that is its corners' own minimum image
            // relative to a[0] (always, near the first triangle), those exact values, so that a
            // shared vertex is the same point in both.
            std::array<Vec3, 3> b = mesh.triangle_positions(live[j]);
            const Vec3 shift = mesh.periods().shift_towards(b[0], a[0]);
            bool consistent = true;
            for (int k = 0; k < 3; ++k) {
                const Vec3 near = mesh.position_near(t[k], a[0]);
                consistent = consistent && (near - (b[k] + shift)).norm() < 1e-9;
            }
            for (int k = 0; k < 3; ++k)
                b[k] = consistent ? mesh.position_near(t[k], a[0]) : Vec3(b[k] + shift);
            Box3d box_b(b[0]);
            box_b.extend(b[1]);
            box_b.extend(b[2]);
            if (!box_a.intersects(box_b))
                continue;
            if (triangles_intersect(a, mesh.triangle(live[i]), b, t))
                ++count;
        }
    }
    return count;
}

/// Longest live edge by the minimum image.
double longest_edge(const SurfaceMesh& mesh) {
    double longest = 0.0;
    for (int ei = 0; ei < mesh.num_edges(); ++ei)
        if (mesh.edge_alive(ei)) {
            const auto p = mesh.edge_positions(ei);
            longest = std::max(longest, (p[1] - p[0]).norm());
        }
    return longest;
}

/// Live edges shorter than `beta` (minimum image) whose ends' stored coordinates along `axis`
/// are more than half a period apart (they cross the seam).
int short_seam_edges(const SurfaceMesh& mesh, double beta, int axis) {
    int count = 0;
    for (int ei = 0; ei < mesh.num_edges(); ++ei) {
        if (!mesh.edge_alive(ei))
            continue;
        const auto p = mesh.edge_positions(ei);
        const Edge& e = mesh.edge(ei);
        const bool seam = std::abs(mesh.position(e[0])[axis] - mesh.position(e[1])[axis]) >
                          0.5 * mesh.periods().length[axis];
        count += seam && (p[1] - p[0]).norm() < beta ? 1 : 0;
    }
    return count;
}

/// Everything a remeshed closed periodic mesh must be.
void expect_valid_periodic(const SurfaceMesh& mesh, double max_edge, const std::string& what) {
    ValidationOptions options;
    options.check_degenerate_area = false;  // checked below by the minimum image
    const auto violations = validate_mesh(mesh, options);
    EXPECT_TRUE(violations.empty()) << what << ": " << violations.size() << " violations, first "
                                    << (violations.empty() ? "" : violations[0].message);
    for (int ei = 0; ei < mesh.num_edges(); ++ei)
        if (mesh.edge_alive(ei)) {
            EXPECT_EQ(mesh.edge_triangles(ei).size(), 2u) << what << ": edge " << ei;
        }
    for (int ti = 0; ti < mesh.num_triangles(); ++ti) {
        if (!mesh.triangle_alive(ti))
            continue;
        const auto p = mesh.triangle_positions(ti);
        const double longest = std::max({(p[1] - p[0]).squaredNorm(), (p[2] - p[1]).squaredNorm(),
                                         (p[0] - p[2]).squaredNorm()});
        EXPECT_GT((p[1] - p[0]).cross(p[2] - p[0]).norm(), 1e-6 * longest)
            << what << ": degenerate triangle " << ti;
    }
    const MeshPeriods& periods = mesh.periods();
    int outside = 0;
    for (int vi = 0; vi < mesh.num_vertices(); ++vi)
        if (mesh.vertex_alive(vi))
            for (int a = 0; a < 3; ++a)
                if (periods.wraps(a) &&
                    !(mesh.position(vi)[a] >= periods.origin[a] &&
                      mesh.position(vi)[a] < periods.origin[a] + periods.length[a]))
                    ++outside;
    EXPECT_EQ(outside, 0) << what << ": vertex coordinates outside the fundamental box";
    EXPECT_LE(longest_edge(mesh), max_edge * (1.0 + 1e-12)) << what;
    EXPECT_EQ(count_intersecting_pairs(mesh), 0) << what << ": self-intersections";
}

/// Counts splits and collapses of edges that cross the seam along `axis` (their ends' stored
/// coordinates more than half a period apart), and checks the parameters observers get.
struct SeamCounter : MeshObserver {
    const SurfaceMesh* mesh = nullptr;
    int axis = 2;
    int seam_splits = 0, seam_collapses = 0, splits = 0, collapses = 0;
    int bad_parameters = 0;
    bool crosses(int a, int b) const {
        const double d = std::abs(mesh->position(a)[axis] - mesh->position(b)[axis]);
        return d > 0.5 * mesh->periods().length[axis];
    }
    void on_edge_split(int v0, int v1, int new_vi, double s) override {
        ++splits;
        seam_splits += crosses(v0, v1) ? 1 : 0;
        // The new vertex sits at the wrapped minimum-image midpoint, reported as s = 1/2.
        const Vec3 mid = 0.5 * (mesh->position(v0) + mesh->position_near(v1, mesh->position(v0)));
        const Vec3 stored = mesh->periods().wrap(mid);
        if (s != 0.5 || (mesh->position(new_vi) - stored).norm() > 1e-12)
            ++bad_parameters;
    }
    void on_edge_collapse(int kept, int removed, double s) override {
        ++collapses;
        // Told after the kept vertex moved to x = k + s (r − k): recover its old place k at
        // the minimum image (s < 1), then compare its stored coordinate with r's.
        if (s < 1.0) {
            const Vec3& x = mesh->position(kept);
            const Vec3 r = mesh->position_near(removed, x);
            const Vec3 k = mesh->periods().wrap((x - s * r) / (1.0 - s));
            const double d = std::abs(k[axis] - mesh->position(removed)[axis]);
            seam_collapses += d > 0.5 * mesh->periods().length[axis] ? 1 : 0;
        }
        if (!(s >= 0.0 && s <= 1.0))
            ++bad_parameters;
    }
};

/// Tube along z of radius R around (0.5, 0.5), period L: rings moved along the axis by
/// z → z + a L/(2π) sin(2π z / L) (a > 0: coarse rings at the seam z = 0, fine in the middle;
/// a < 0: the reverse), then the fundamental box's origin moved by `origin_z` (the seam then
/// cuts through triangles, not along a ring).
SurfaceMesh graded_tube(double radius, double length, int around, int along, double a,
                        double origin_z) {
    SurfaceMesh mesh =
        testing::periodic_tube(radius, Vec3(0.5, 0.5, 0.0), 2, length, around, along);
    for (int vi = 0; vi < mesh.num_vertices(); ++vi) {
        Vec3 p = mesh.position(vi);
        p.z() += a * length / (2.0 * PI) * std::sin(2.0 * PI * p.z() / length);
        mesh.set_position(vi, p);
    }
    MeshPeriods periods = mesh.periods();
    periods.origin.z() = origin_z;
    mesh.set_periods(periods);
    return mesh;
}

double max_radius_error(const SurfaceMesh& mesh, double radius) {
    double worst = 0.0;
    for (int vi = 0; vi < mesh.num_vertices(); ++vi)
        if (mesh.vertex_alive(vi)) {
            const Vec3& p = mesh.position(vi);
            worst = std::max(worst, std::abs(std::hypot(p.x() - 0.5, p.y() - 0.5) - radius));
        }
    return worst / radius;
}

// ---- element hash -------------------------------------------------------------------------

/// The brute-force answer of a query: elements whose minimum-image box, at one of its images
/// by −1, 0, +1 periods along each wrapping axis, overlaps `box`.
std::vector<int> brute_force_query(const SurfaceMesh& mesh, const std::vector<Box3d>& boxes,
                                   const Box3d& box) {
    const MeshPeriods& periods = mesh.periods();
    std::vector<int> out;
    for (size_t id = 0; id < boxes.size(); ++id) {
        if (boxes[id].isEmpty())
            continue;
        bool hit = false;
        for (int i = -1; i <= 1 && !hit; ++i)
            for (int j = -1; j <= 1 && !hit; ++j)
                for (int k = -1; k <= 1 && !hit; ++k) {
                    const Vec3 shift(i * periods.length[0], j * periods.length[1],
                                     k * periods.length[2]);
                    if ((!periods.wraps(0) && i) || (!periods.wraps(1) && j) ||
                        (!periods.wraps(2) && k))
                        continue;
                    hit = Box3d(boxes[id].min() + shift, boxes[id].max() + shift).intersects(box);
                }
        if (hit)
            out.push_back(static_cast<int>(id));
    }
    return out;
}

struct AllBoxes {
    std::vector<Box3d> vertices, edges, triangles;
};
AllBoxes all_boxes(const SurfaceMesh& mesh) {
    AllBoxes b;
    b.vertices.resize(static_cast<size_t>(mesh.num_vertices()));
    b.edges.resize(static_cast<size_t>(mesh.num_edges()));
    b.triangles.resize(static_cast<size_t>(mesh.num_triangles()));
    for (int vi = 0; vi < mesh.num_vertices(); ++vi)
        if (mesh.vertex_alive(vi))
            b.vertices[static_cast<size_t>(vi)] = Box3d(mesh.position(vi));
    for (int ei = 0; ei < mesh.num_edges(); ++ei)
        if (mesh.edge_alive(ei))
            b.edges[static_cast<size_t>(ei)] = edge_box(mesh, ei);
    for (int ti = 0; ti < mesh.num_triangles(); ++ti)
        if (mesh.triangle_alive(ti))
            b.triangles[static_cast<size_t>(ti)] = triangle_box(mesh, ti);
    return b;
}

/// Compares every query of `hash` with brute force for random boxes near the fundamental box's
/// faces; returns how many found elements lie across a seam from the query (at a nonzero image).
int compare_queries(const SurfaceMesh& mesh, const ElementHash& hash, std::mt19937& rng,
                    int queries) {
    const AllBoxes boxes = all_boxes(mesh);
    const MeshPeriods& periods = mesh.periods();
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    int across = 0;
    std::vector<int> found;
    for (int q = 0; q < queries; ++q) {
        // A reference point in the box (half of them within 0.1 of a face along each wrapping
        // axis) and a query box of up to 0.2 around it.
        Vec3 centre;
        for (int a = 0; a < 3; ++a) {
            const double len = periods.wraps(a) ? periods.length[a] : 1.0;
            double u = unit(rng);
            if (periods.wraps(a) && q % 2 == 0)
                u = u < 0.5 ? 0.1 * u : 1.0 - 0.1 * (u - 0.5);
            centre[a] = periods.origin[a] + u * len;
        }
        const Vec3 half(0.1 * unit(rng), 0.1 * unit(rng), 0.1 * unit(rng));
        const Box3d box(centre - half, centre + half);
        hash.query_vertices(box, found);
        EXPECT_EQ(found, brute_force_query(mesh, boxes.vertices, box)) << "vertices, query " << q;
        hash.query_edges(box, found);
        EXPECT_EQ(found, brute_force_query(mesh, boxes.edges, box)) << "edges, query " << q;
        hash.query_triangles(box, found);
        EXPECT_EQ(found, brute_force_query(mesh, boxes.triangles, box)) << "triangles, query " << q;
        for (int ti : found)
            across += boxes.triangles[static_cast<size_t>(ti)].intersects(box) ? 0 : 1;
    }
    return across;
}

TEST(PeriodicElementHash, QueriesEqualThePeriodicBruteForceOnATubeAndASheet) {
    std::mt19937 rng(39);
    SurfaceMesh tube = graded_tube(0.25, 1.0, 14, 12, 0.3, 0.137);
    SurfaceMesh sheet = testing::periodic_sheet(1.0, 0.8, 12, 10, [](double x, double y) {
        return 0.3 + 0.05 * std::sin(2 * PI * x) * std::cos(2 * PI * y / 0.8);
    });
    MeshPeriods sheet_periods = sheet.periods();
    sheet_periods.origin = Vec3(-0.21, 0.33, 0.0);
    sheet.set_periods(sheet_periods);
    for (SurfaceMesh* mesh : {&tube, &sheet}) {
        ElementHash hash(*mesh, 0.08);
        EXPECT_GT(compare_queries(*mesh, hash, rng, 200), 0) << "no element found across a seam";
        // Move a few vertices (some across the seam), refresh, and compare again.
        std::uniform_int_distribution<int> pick(0, mesh->num_vertices() - 1);
        for (int m = 0; m < 10; ++m) {
            const int vi = pick(rng);
            hash.begin_update(*mesh, {vi});
            Vec3 p = mesh->position(vi);
            p += Vec3(0.03, -0.02, 0.04) * (m % 2 ? 1.0 : -1.0);
            for (int a = 0; a < 3; ++a)
                if (mesh->periods().wraps(a) && m % 3 == 0)
                    p[a] = mesh->periods().origin[a] + 0.001 * (m % 2);  // onto a face
            mesh->set_position(vi, mesh->periods().wrap(p));
            hash.refresh(*mesh, {vi});
        }
        compare_queries(*mesh, hash, rng, 200);
    }
}

// ---- local safety across the seam ----------------------------------------------------------

/// Two small triangles on either side of the seam z = 0 ≡ 1 (period 1 along z): T1 at
/// z = 0.98, T2 at z ≈ 0.02 below it.
SurfaceMesh two_triangles_across_the_seam(bool periodic) {
    SurfaceMesh mesh({Vec3(0.0, 0.0, 0.98), Vec3(0.1, 0.0, 0.98), Vec3(0.0, 0.1, 0.98),
                      Vec3(0.02, 0.02, 0.02), Vec3(0.12, 0.02, 0.03), Vec3(0.02, 0.12, 0.03)},
                     {{0, 1, 2}, {3, 4, 5}});
    if (periodic) {
        MeshPeriods periods;
        periods.length.z() = 1.0;
        mesh.set_periods(periods);
    }
    return mesh;
}

TEST(PeriodicLocalSafety, APseudoMotionThroughTheSeamHitsTheTriangleOnTheOtherSide) {
    for (bool periodic : {false, true}) {
        const SurfaceMesh mesh = two_triangles_across_the_seam(periodic);
        const ElementHash hash(mesh, 0.05);
        // Vertex 3 moves down through z = 0 to −0.05 (≡ 0.95): through T1 at z = −0.02 ≡ 0.98.
        PseudoMotion motion;
        motion.vertices = {3};
        motion.x_t1 = {Vec3(0.02, 0.02, -0.05)};
        EXPECT_EQ(pseudo_motion_collides(mesh, hash, motion), periodic) << periodic;
        // The same end given at its wrapped image: the same motion.
        motion.x_t1 = {Vec3(0.02, 0.02, 0.95)};
        if (periodic) {
            EXPECT_TRUE(pseudo_motion_collides(mesh, hash, motion));
        }
        // A short motion that stays clear of T1.
        motion.x_t1 = {Vec3(0.02, 0.02, 0.0)};
        EXPECT_FALSE(pseudo_motion_collides(mesh, hash, motion)) << periodic;
        // A candidate triangle reaching through the seam intersects T1; one that does not, not.
        CandidateTriangles candidates;
        candidates.triangles = {{6, 4, 5}};
        candidates.overrides = {{6, Vec3(0.02, 0.02, -0.05)}};
        EXPECT_EQ(candidate_triangles_intersect(mesh, hash, candidates, {1}), periodic);
        candidates.overrides = {{6, Vec3(0.02, 0.02, 0.01)}};
        EXPECT_FALSE(candidate_triangles_intersect(mesh, hash, candidates, {1}));
    }
}

TEST(PeriodicLocalSafety, TheBruteForceIntersectionCheckOfTheseTestsSeesTheSeam) {
    // T2 pushed through the seam onto T1's image: one intersecting pair when periodic, none
    // otherwise (so that the checks of the remeshed meshes below can fail).
    for (bool periodic : {false, true}) {
        SurfaceMesh mesh = two_triangles_across_the_seam(periodic);
        EXPECT_EQ(count_intersecting_pairs(mesh), 0);
        mesh.set_position(3, mesh.periods().wrap(Vec3(0.02, 0.02, -0.05)));
        EXPECT_EQ(count_intersecting_pairs(mesh), periodic ? 1 : 0) << periodic;
    }
}

// ---- sizing --------------------------------------------------------------------------------

TEST(PeriodicSizing, AlphaIsClampedToTheSmallestPeriodOverTheRatio) {
    const SurfaceMesh tube = testing::periodic_tube(0.2, Vec3(0.5, 0.5, 0.0), 2, 0.8, 12, 10);
    RemeshOptions options;
    const EdgeSizing coarse(tube, options, 0.2);  // α = 0.3 > 0.8 / 8
    EXPECT_DOUBLE_EQ(coarse.limits().max_edge_length, 0.8 / MeshPeriods::PERIOD_TO_EDGE_RATIO);
    EXPECT_DOUBLE_EQ(coarse.limits().min_edge_length / coarse.limits().max_edge_length,
                     options.min_edge_fraction / options.max_edge_fraction);
    const EdgeSizing fine(tube, options, 0.05);  // α = 0.075: unchanged
    EXPECT_DOUBLE_EQ(fine.limits().max_edge_length, remesh_limits(options, 0.05).max_edge_length);
    SurfaceMesh open = tube;
    open.set_periods(MeshPeriods{});
    EXPECT_DOUBLE_EQ(EdgeSizing(open, options, 0.2).limits().max_edge_length,
                     remesh_limits(options, 0.2).max_edge_length);
}

// ---- improve_mesh on periodic meshes -------------------------------------------------------

struct TubeCase {
    double xi;     ///< target ξ
    double grade;  ///< a of graded_tube
    int around;    ///< vertices per ring
    bool seam_splits, seam_collapses;
    bool fitted = false;  ///< fitted-surface points and smoothing
};

TEST(PeriodicImprove, TubeStaysAValidIntersectionFreeTubeOfTheSameVolume) {
    const double radius = 0.25, length = 1.0;
    // Fine target, coarse seam (splits there); coarse target (α clamped to L/8), fine seam
    // (collapses there); a uniform tube already in range; the first two with fitted points (with
    // two smoothing steps onto the fitted surface the fine seam rings spread out before any
    // collapse: no short seam edge is left, but none needs collapsing across the seam).
    for (const TubeCase& c :
         {TubeCase{0.05, 0.6, 14, true, false}, TubeCase{0.09, -0.8, 24, false, true},
          TubeCase{0.1, 0.0, 14, false, false}, TubeCase{0.05, 0.6, 14, true, false, true},
          TubeCase{0.09, -0.8, 24, false, false, true}}) {
        // The seam along a ring (z = 0), and through the seam ring's triangles (z = −0.008).
        for (double origin_z : {0.0, -0.008}) {
            SurfaceMesh mesh = graded_tube(radius, length, c.around, 12, c.grade, origin_z);
            const std::string what = "xi " + std::to_string(c.xi) + " grade " +
                                     std::to_string(c.grade) + " origin " +
                                     std::to_string(origin_z) + (c.fitted ? " fitted" : "");
            const double v0 = volume_along(mesh, 0);
            EXPECT_GT(v0, 0.0);
            SeamCounter counter;
            counter.mesh = &mesh;
            mesh.add_observer(&counter);
            RemeshOptions options;
            if (c.fitted) {
                // New and smoothed vertices on the fitted surface (surface_fit.h).
                options.split_on_fitted_surface = true;
                options.collapse_on_fitted_surface = true;
                options.smoothing_onto_fitted_surface = true;
                options.smoothing_iterations = 2;
            }
            ImproveContext context;
            context.xi = c.xi;
            context.allow_topology_changes = false;
            for (int it = 0; it < 4; ++it)
                improve_mesh(mesh, options, context);
            mesh.remove_observer(&counter);
            const RemeshLimits limits = EdgeSizing(mesh, options, c.xi).limits();
            const double alpha = limits.max_edge_length;
            EXPECT_LE(alpha, length / MeshPeriods::PERIOD_TO_EDGE_RATIO);
            EXPECT_EQ(short_seam_edges(mesh, limits.min_edge_length, 2), 0) << what;
            expect_valid_periodic(mesh, alpha, what);
            const double v1 = volume_along(mesh, 0);
            // Between the inscribed start and the true cylinder: the new vertices go onto the
            // surface, so refinement fills the chords' deficit towards π r² L.
            const double exact = PI * radius * radius * length;
            EXPECT_GT(v1 / v0, 1.0 - 2e-3) << what;
            EXPECT_LT(v1 / exact, 1.0 + 2e-3) << what;
            EXPECT_NEAR(volume_along(mesh, 1), v1, 1e-12) << what;
            EXPECT_LT(max_radius_error(mesh, radius), 0.03) << what;
            EXPECT_EQ(counter.bad_parameters, 0) << what;
            if (c.seam_splits) {
                EXPECT_GT(counter.seam_splits, 0) << what;
            }
            if (c.seam_collapses) {
                EXPECT_GT(counter.seam_collapses, 0) << what;
            }
            std::cout << what << ": " << mesh.count_live_vertices() << " vertices, splits "
                      << counter.splits << " (" << counter.seam_splits << " across the seam), "
                      << "collapses " << counter.collapses << " (" << counter.seam_collapses
                      << "), volume ratio " << v1 / v0 << " (" << v0 / exact << " -> " << v1 / exact
                      << " of the cylinder), radius error " << max_radius_error(mesh, radius)
                      << "\n";
        }
    }
}

TEST(PeriodicImprove, DoublyPeriodicWavySheetKeepsItsShape) {
    const double lx = 1.0, ly = 0.8, h0 = 0.3, amplitude = 0.04;
    const auto height = [&](double x, double y) {
        return h0 + amplitude * std::sin(2 * PI * x / lx) * std::cos(2 * PI * y / ly);
    };
    // A fine target on a coarse sheet (splits) and a coarse one (α clamped to ly / 8) on a
    // fine sheet (collapses).
    for (double xi : {0.04, 0.1}) {
        SurfaceMesh mesh = xi < 0.05 ? testing::periodic_sheet(lx, ly, 14, 12, height)
                                     : testing::periodic_sheet(lx, ly, 34, 28, height);
        MeshPeriods periods = mesh.periods();
        periods.origin = Vec3(0.07, -0.11, 0.0);
        mesh.set_periods(periods);
        SeamCounter counter;
        counter.mesh = &mesh;
        counter.axis = 0;
        mesh.add_observer(&counter);
        RemeshOptions options;
        ImproveContext context;
        context.xi = xi;
        context.allow_topology_changes = false;
        for (int it = 0; it < 4; ++it)
            improve_mesh(mesh, options, context);
        mesh.remove_observer(&counter);
        const std::string what = "xi " + std::to_string(xi);
        const RemeshLimits limits = EdgeSizing(mesh, options, xi).limits();
        expect_valid_periodic(mesh, limits.max_edge_length, what);
        EXPECT_EQ(short_seam_edges(mesh, limits.min_edge_length, 0), 0) << what;
        EXPECT_EQ(short_seam_edges(mesh, limits.min_edge_length, 1), 0) << what;
        EXPECT_GT(counter.splits + counter.collapses, 0) << what;
        EXPECT_GT(counter.seam_splits + counter.seam_collapses, 0) << what;
        // Liquid below the surface: ∫∫ h = h0 lx ly (the wave integrates to 0).
        EXPECT_NEAR(volume_along(mesh, 2) / (h0 * lx * ly), 1.0, 2e-3) << what;
        double worst = 0.0;
        for (int vi = 0; vi < mesh.num_vertices(); ++vi)
            if (mesh.vertex_alive(vi)) {
                const Vec3& p = mesh.position(vi);
                worst = std::max(worst, std::abs(p.z() - height(p.x(), p.y())));
            }
        EXPECT_LT(worst, 0.15 * amplitude) << what;
        std::cout << what << ": " << mesh.count_live_vertices() << " vertices, splits "
                  << counter.splits << ", collapses " << counter.collapses << ", across x seam "
                  << counter.seam_splits + counter.seam_collapses << ", height error " << worst
                  << ", volume ratio " << volume_along(mesh, 2) / (h0 * lx * ly) << "\n";
    }
}

}  // namespace
}  // namespace meniscus::tracker
