#include "coupling/rasterize.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <vector>

namespace meniscus::coupling {

namespace {

/// The smallest band half width (cells) for which the breadth-first sign fill is exact.
constexpr double MIN_HALF_WIDTH_CELLS = 2.0;
/// The region of space no triangle encloses (tracker convention).
constexpr int AMBIENT_REGION = 0;

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point start) {
    return std::chrono::duration<double>(Clock::now() - start).count();
}

/// Gives every cell outside the band (φ not yet set, marked by a zero `sign`) the sign of the
/// band cells its face-connected component touches; breadth first from all band cells.
void fill_signs(std::vector<std::int8_t>& sign, int nx, int ny, int nz) {
    std::vector<size_t> queue;
    queue.reserve(sign.size());
    for (size_t flat = 0; flat < sign.size(); ++flat)
        if (sign[flat] != 0)
            queue.push_back(flat);
    const size_t sx = 1;
    const size_t sy = static_cast<size_t>(nx);
    const size_t sz = static_cast<size_t>(nx) * static_cast<size_t>(ny);
    for (size_t head = 0; head < queue.size(); ++head) {
        const size_t flat = queue[head];
        const int i = static_cast<int>(flat % sy);
        const int j = static_cast<int>((flat / sy) % static_cast<size_t>(ny));
        const int k = static_cast<int>(flat / sz);
        const std::int8_t s = sign[flat];
        const auto visit = [&](size_t neighbour) {
            if (sign[neighbour] == 0) {
                sign[neighbour] = s;
                queue.push_back(neighbour);
            }
        };
        if (i > 0)
            visit(flat - sx);
        if (i + 1 < nx)
            visit(flat + sx);
        if (j > 0)
            visit(flat - sy);
        if (j + 1 < ny)
            visit(flat + sy);
        if (k > 0)
            visit(flat - sz);
        if (k + 1 < nz)
            visit(flat + sz);
    }
}

}  // namespace

void RasterizeOptions::validate() const {
    if (!(half_width_cells >= MIN_HALF_WIDTH_CELLS) || !std::isfinite(half_width_cells))
        throw std::invalid_argument("half_width_cells: expected a number >= 2");
}

RasterizeResult rasterize_mesh(const tracker::SurfaceMesh& mesh, const fluid::MacGrid& grid,
                               const RasterizeOptions& options) {
    options.validate();
    const Clock::time_point start = Clock::now();
    const int nx = grid.nx();
    const int ny = grid.ny();
    const int nz = grid.nz();
    const double dx = grid.dx();

    RasterizeResult result;
    result.liquid_region = options.liquid_region;
    result.phi.resize(nx, ny, nz, 0.0);
    result.closest_triangle.resize(nx, ny, nz, tracker::INVALID_INDEX);

    // 1–2. The signed band on the cell centres (mesh_band.h): negative in the liquid.
    VoxelLattice lattice;
    lattice.origin = grid.cell_centre(0, 0, 0);
    lattice.voxel_size = dx;
    SignedBandOptions band_options;
    band_options.half_width_voxels = options.half_width_cells;
    band_options.inside_region = options.liquid_region;
    VoxelBounds cells;
    cells.hi = {nx - 1, ny - 1, nz - 1};
    const SignedBand band = signed_band(mesh, lattice, band_options, &cells);
    result.timings.mesh_to_volume = band.seconds_mesh_to_volume;
    result.timings.band = band.seconds_exact;

    std::vector<std::int8_t> sign(result.phi.size(), 0);
    double band_value = options.half_width_cells * dx;
    for (const BandVoxel& v : band.voxels) {
        const size_t flat = result.phi.index(v.ijk[0], v.ijk[1], v.ijk[2]);
        result.phi[flat] = v.phi;
        result.closest_triangle[flat] = v.closest_triangle;
        sign[flat] = std::signbit(v.phi) ? -1 : 1;
        band_value = std::max(band_value, std::abs(v.phi));
    }
    result.band_cells = static_cast<long long>(band.voxels.size());
    result.band_value = band_value;

    // 3. Cells outside the band: sign of the connected band cells.
    const Clock::time_point fill_start = Clock::now();
    if (band.voxels.empty()) {
        const int region = region_at(mesh, grid.cell_centre(0, 0, 0), AMBIENT_REGION);
        std::fill(sign.begin(), sign.end(), region == options.liquid_region ? -1 : 1);
    } else {
        fill_signs(sign, nx, ny, nz);
    }
    for (size_t flat = 0; flat < sign.size(); ++flat)
        if (result.closest_triangle[flat] == tracker::INVALID_INDEX)
            result.phi[flat] = sign[flat] < 0 ? -band_value : band_value;
    result.timings.sign_fill = seconds_since(fill_start);
    result.timings.total = seconds_since(start);
    return result;
}

}  // namespace meniscus::coupling
