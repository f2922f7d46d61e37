#include "coupling/levelset_reference.h"

#include <openvdb/math/Stencils.h>
#include <openvdb/openvdb.h>
#include <openvdb/tools/Interpolation.h>
#include <openvdb/tools/LevelSetTracker.h>
#include <openvdb/tools/Morphology.h>
#include <openvdb/tools/SignedFloodFill.h>
#include <openvdb/tree/LeafManager.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace meniscus::coupling {

namespace {

using Eigen::Vector3d;

/// Voxels whose shape value is below this multiple of the band half width are projected onto
/// the surface. The shapes' values are 1-Lipschitz (exact distances or smaller), so every voxel
/// within the band qualifies; the factor leaves room for shapes that are only close to that.
constexpr double CANDIDATE_VALUE_FACTOR = 1.5;
/// Extra voxels around the shape's bounds scanned for band voxels.
constexpr int SCAN_MARGIN_VOXELS = 2;
/// Closest-point projection (tracker::projected_signed_distance): the tangential residual
/// (fraction of Δx) that ends it.
constexpr double PROJECTION_TOLERANCE_FRACTION = 1e-7;
/// Below this central-difference |∇φ| the curvature step uses the Laplacian (see the step).
constexpr float DEGENERATE_GRADIENT = 0.5f;
/// Largest motion of a voxel value in one curvature step, in voxels (see the step).
constexpr double MAX_STEP_VOXELS = 0.5;
/// Largest index extent of the scanned box (voxels per axis).
constexpr double MAX_VOXELS_PER_AXIS = 2147483000.0;

using Clock = std::chrono::steady_clock;

openvdb::FloatGrid::Ptr initial_band(const tracker::ImplicitShape& shape, double dx,
                                     int half_width) {
    const tracker::Box3 bounds = shape.bounds();
    if (!bounds.min().allFinite() || !bounds.max().allFinite() || bounds.isEmpty())
        throw std::invalid_argument(
            "LevelSetReference: the shape's bounds must be finite and non-empty");
    const double background = half_width * dx;
    openvdb::FloatGrid::Ptr grid = openvdb::FloatGrid::create(static_cast<float>(background));
    grid->setTransform(openvdb::math::Transform::createLinearTransform(dx));
    grid->setGridClass(openvdb::GRID_LEVEL_SET);
    const int margin = half_width + SCAN_MARGIN_VOXELS;
    Eigen::Vector3i lo, hi;
    for (int a = 0; a < 3; ++a) {
        const double l = std::floor(bounds.min()[a] / dx) - margin;
        const double h = std::ceil(bounds.max()[a] / dx) + margin;
        if (std::abs(l) > MAX_VOXELS_PER_AXIS || std::abs(h) > MAX_VOXELS_PER_AXIS)
            throw std::runtime_error(
                "LevelSetReference: the shape is too large for the voxel size");
        lo[a] = static_cast<int>(l);
        hi[a] = static_cast<int>(h);
    }
    const double candidate = CANDIDATE_VALUE_FACTOR * background;
    const double tolerance = PROJECTION_TOLERANCE_FRACTION * dx;
    openvdb::FloatGrid::Accessor acc = grid->getAccessor();
    for (int i = lo.x(); i <= hi.x(); ++i)
        for (int j = lo.y(); j <= hi.y(); ++j)
            for (int k = lo.z(); k <= hi.z(); ++k) {
                const Vector3d x(i * dx, j * dx, k * dx);
                if (!(std::abs(shape.value(x)) < candidate))
                    continue;
                const double d = tracker::projected_signed_distance(shape, x, tolerance);
                if (std::abs(d) < background)
                    acc.setValue(openvdb::Coord(i, j, k), static_cast<float>(d));
            }
    openvdb::tools::signedFloodFill(grid->tree());
    return grid;
}

/// Rebuilds the band around the moved surface without moving the surface: dilates it by one
/// voxel, runs `iterations` Eikonal iterations (OpenVDB's LevelSetTracker::normalize) on every
/// band voxel EXCEPT the interface voxels (those with a face neighbour of the other sign), which
/// keep their values so the zero crossings stay where the curvature step put them, then trims.
/// (OpenVDB's own track() renormalizes the interface voxels too; its smoothed-sign iterations
/// shift the zero set a little every time — see the header.) An interface voxel's true distance
/// is at most Δx; one whose value says more is stale (the surface swept past it, e.g. a tip
/// retracting after a pinch-off) and gets the distance estimate of OpenVDB's fast sweeping
/// (FastSweeping.h InitSdf): along each axis with a sign change the linearly interpolated
/// crossing distance dₐ, combined as 1/sqrt(Σ 1/dₐ²), exact for a plane.
void rebuild_band(openvdb::FloatGrid& grid, int iterations) {
    using Tracker = openvdb::tools::LevelSetTracker<openvdb::FloatGrid>;
    const float dx = static_cast<float>(grid.voxelSize()[0]);
    Tracker band(grid);
    band.setNormCount(iterations);
    openvdb::tools::dilateActiveValues(band.leafs(), 1, openvdb::tools::NN_FACE,
                                       openvdb::tools::IGNORE_TILES);
    Tracker::MaskTreeType free_voxels(grid.tree(), false, openvdb::TopologyCopy());
    std::vector<std::pair<openvdb::Coord, float>> stale;
    {
        openvdb::FloatGrid::ConstAccessor acc = grid.getConstAccessor();
        auto mask_acc = openvdb::tree::ValueAccessor<Tracker::MaskTreeType>(free_voxels);
        for (auto it = grid.cbeginValueOn(); it; ++it) {
            const openvdb::Coord ijk = it.getCoord();
            const float value = *it;
            const bool inside = value < 0.0f;
            bool interface = false;
            double inverse_square_sum = 0.0;
            for (int a = 0; a < 3; ++a) {
                double nearest = std::numeric_limits<double>::infinity();  // in voxels
                for (int side = -1; side <= 1; side += 2) {
                    openvdb::Coord nb = ijk;
                    nb[a] += side;
                    const float other = acc.getValue(nb);
                    if ((other < 0.0f) != inside) {
                        interface = true;
                        nearest = std::min(nearest, static_cast<double>(value) /
                                                        (static_cast<double>(value) - other));
                    }
                }
                if (nearest < std::numeric_limits<double>::infinity() && nearest > 0.0)
                    inverse_square_sum += 1.0 / (nearest * nearest);
            }
            if (!interface)
                continue;
            mask_acc.setValueOff(ijk);
            if (std::abs(value) > dx)
                stale.emplace_back(ijk, static_cast<float>(std::copysign(
                                            dx / std::sqrt(inverse_square_sum), value)));
        }
    }
    openvdb::FloatGrid::Accessor acc = grid.getAccessor();
    for (const auto& [ijk, value] : stale)
        acc.setValueOnly(ijk, value);
    band.normalize(&free_voxels);
    band.prune();
}

}  // namespace

void LevelSetReferenceOptions::validate() const {
    if (!(voxel_size > 0.0) || !std::isfinite(voxel_size))
        throw std::invalid_argument("LevelSetReferenceOptions::voxel_size must be finite and > 0");
    if (!(end_time >= 0.0) || !std::isfinite(end_time))
        throw std::invalid_argument("LevelSetReferenceOptions::end_time must be finite and >= 0");
    if (half_width_voxels < 3)
        throw std::invalid_argument("LevelSetReferenceOptions::half_width_voxels must be >= 3");
    if (!(cfl > 0.0 && cfl <= 1.0))
        throw std::invalid_argument("LevelSetReferenceOptions::cfl must be in (0, 1]");
    if (renormalization_iterations < 1)
        throw std::invalid_argument(
            "LevelSetReferenceOptions::renormalization_iterations must be >= 1");
}

struct LevelSetReference::Impl {
    openvdb::FloatGrid::Ptr grid;
    double dx = 0.0;
    double half_width = 0.0;  // m
    LevelSetReferenceStats stats;
};

LevelSetReference::LevelSetReference(const tracker::ImplicitShape& shape,
                                     const LevelSetReferenceOptions& options)
    : m_impl(std::make_unique<Impl>()) {
    options.validate();
    const auto start = Clock::now();
    openvdb::initialize();
    Impl& m = *m_impl;
    const double dx = options.voxel_size;
    m.dx = dx;
    m.half_width = options.half_width_voxels * dx;
    m.grid = initial_band(shape, dx, options.half_width_voxels);
    m.stats.initial_voxels = static_cast<long long>(m.grid->activeVoxelCount());

    const double max_dt = options.cfl * dx * dx / 6.0;
    const long steps =
        options.end_time > 0.0 ? static_cast<long>(std::ceil(options.end_time / max_dt)) : 0;
    const double dt = steps > 0 ? options.end_time / static_cast<double>(steps) : 0.0;
    m.stats.time_step = dt;
    using LeafManager = openvdb::tree::LeafManager<openvdb::FloatTree>;
    using Leaf = openvdb::FloatTree::LeafNodeType;
    for (long n = 0; n < steps; ++n) {
        LeafManager leafs(m.grid->tree(), 1);  // auxiliary buffer 1 starts as a copy
        if (leafs.leafCount() == 0)
            break;  // the surface has vanished
        const openvdb::FloatGrid& grid = *m.grid;
        leafs.foreach ([&](Leaf& leaf, size_t li) {
            openvdb::math::CurvatureStencil<openvdb::FloatGrid> stencil(grid, dx);
            float* out = leafs.getBuffer(li, 1).data();
            for (auto it = leaf.cbeginValueOn(); it; ++it) {
                stencil.moveTo(it);
                // meanCurvatureNormGrad() = (κ₁ + κ₂)/2 · |∇φ|. Where the central-difference
                // gradient (≈ 1 in the renormalized band) nearly vanishes — a voxel-sized blob
                // or the instant of a pinch — the normal is undefined and OpenVDB returns 0,
                // which would freeze such a blob for ever; there use κ₁ + κ₂ = Δφ, exact for a
                // signed distance.
                const double speed =
                    stencil.gradient().length() < DEGENERATE_GRADIENT
                        ? static_cast<double>(stencil.laplacian())
                        : 2.0 * static_cast<double>(stencil.meanCurvatureNormGrad());
                // The band follows the surface by one voxel per step: at under-resolved
                // singular events (curvature beyond 6/Δx) the motion is capped at MAX_STEP_VOXELS.
                const double move =
                    std::clamp(dt * speed, -MAX_STEP_VOXELS * dx, MAX_STEP_VOXELS * dx);
                out[it.pos()] = static_cast<float>(static_cast<double>(*it) + move);
            }
        });
        leafs.swapLeafBuffer(1);
        ++m.stats.steps;
        rebuild_band(*m.grid, options.renormalization_iterations);
    }
    m.stats.final_voxels = static_cast<long long>(m.grid->activeVoxelCount());
    m.stats.seconds = std::chrono::duration<double>(Clock::now() - start).count();
}

LevelSetReference::~LevelSetReference() = default;
LevelSetReference::LevelSetReference(LevelSetReference&&) noexcept = default;
LevelSetReference& LevelSetReference::operator=(LevelSetReference&&) noexcept = default;

double LevelSetReference::distance(const Eigen::Vector3d& x) const {
    const Impl& m = *m_impl;
    const openvdb::Vec3R index(x.x() / m.dx, x.y() / m.dx, x.z() / m.dx);
    float value = 0.0f;
    openvdb::tools::QuadraticSampler::sample(m.grid->tree(), index, value);
    return std::clamp(static_cast<double>(value), -m.half_width, m.half_width);
}

double LevelSetReference::band_half_width() const {
    return m_impl->half_width;
}

const LevelSetReferenceStats& LevelSetReference::stats() const {
    return m_impl->stats;
}

}  // namespace meniscus::coupling
