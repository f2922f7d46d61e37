#include "mesh_rings.h"

#include <algorithm>
#include <vector>

namespace meniscus::tracker::testing {

int two_ring_size(const SurfaceMesh& mesh, int vi) {
    std::vector<int> ring;
    for (int ti : mesh.vertex_triangles(vi))
        for (int w : mesh.triangle(ti))
            for (int tj : mesh.vertex_triangles(w))
                for (int x : mesh.triangle(tj))
                    ring.push_back(x);
    std::sort(ring.begin(), ring.end());
    return static_cast<int>(std::unique(ring.begin(), ring.end()) - ring.begin());
}

}  // namespace meniscus::tracker::testing
