#include "periodic_meshes.h"

#include <cmath>
#include <stdexcept>

namespace meniscus::tracker::testing {

SurfaceMesh periodic_tube(double radius, const Vec3& centre, int axis, double length, int around,
                          int along, const std::function<double(double)>& radius_at) {
    if (along < 2 || along % 2 != 0 || around < 3)
        throw std::invalid_argument("periodic_tube: needs an even number of rings and 3 per ring");
    const int u = (axis + 1) % 3, v = (axis + 2) % 3;
    std::vector<Vec3> x;
    std::vector<Triangle> t;
    for (int j = 0; j < along; ++j) {
        const double s = length * j / along;
        const double r = radius * (radius_at ? radius_at(s) : 1.0);
        for (int i = 0; i < around; ++i) {
            const double theta = 2.0 * M_PI * (i + 0.5 * (j % 2)) / around;
            Vec3 p = centre;
            p[u] += r * std::cos(theta);
            p[v] += r * std::sin(theta);
            p[axis] = s;
            x.push_back(p);
        }
    }
    const auto id = [&](int i, int j) {
        return ((j + along) % along) * around + (i + around) % around;
    };
    for (int j = 0; j < along; ++j)
        for (int i = 0; i < around; ++i) {
            // Odd rings are turned by half a step: ring j+1's vertex i sits between i and i+1 of
            // ring j when j is even, between i−1 and i when j is odd.
            if (j % 2 == 0) {
                t.push_back({id(i, j), id(i + 1, j), id(i, j + 1)});
                t.push_back({id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)});
            } else {
                t.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
                t.push_back({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
            }
        }
    SurfaceMesh mesh(std::move(x), t);
    MeshPeriods periods;
    periods.length[axis] = length;
    mesh.set_periods(periods);
    return mesh;
}

SurfaceMesh periodic_sheet(double lx, double ly, int nx, int ny,
                           const std::function<double(double, double)>& height) {
    std::vector<Vec3> x;
    std::vector<Triangle> t;
    for (int j = 0; j < ny; ++j)
        for (int i = 0; i < nx; ++i) {
            const double px = lx * i / nx, py = ly * j / ny;
            x.emplace_back(px, py, height(px, py));
        }
    const auto id = [&](int i, int j) { return ((j + ny) % ny) * nx + (i + nx) % nx; };
    for (int j = 0; j < ny; ++j)
        for (int i = 0; i < nx; ++i) {
            t.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
            t.push_back({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
        }
    SurfaceMesh mesh(std::move(x), t);
    MeshPeriods periods;
    periods.length = Vec3(lx, ly, 0.0);
    mesh.set_periods(periods);
    return mesh;
}

}  // namespace meniscus::tracker::testing
