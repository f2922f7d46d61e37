#include "fluid/extrapolation.h"

#include <array>
#include <cstdint>
#include <stdexcept>
#include <vector>

namespace meniscus::fluid {

namespace {

/// Status of a face during extrapolation.
enum FaceState : std::uint8_t { UNKNOWN = 0, KNOWN = 1, WALL = 2 };

}  // namespace

void extrapolate_velocity(MacGrid& grid, const InterfaceInput& interface, int layers) {
    if (layers < 0) {
        throw std::invalid_argument("extrapolate_velocity: layers must be non-negative");
    }
    interface.validate(grid);
    const Array3<double>& phi = interface.phi;
    const Periodicity& periodic = grid.periodic();
    const std::array<int, 3> cells = {grid.nx(), grid.ny(), grid.nz()};
    for (int a = 0; a < 3; ++a) {
        Array3<double>& faces = grid.velocity(a);
        const int n_axis = grid.cells(a);
        const bool seam = periodic[static_cast<std::size_t>(a)] && n_axis > 1;
        Array3<std::uint8_t> state(faces.ni(), faces.nj(), faces.nk(), UNKNOWN);
        for (int k = 0; k < faces.nk(); ++k) {
            for (int j = 0; j < faces.nj(); ++j) {
                for (int i = 0; i < faces.ni(); ++i) {
                    std::array<int, 3> lo = {i, j, k};
                    const int along = lo[a];
                    if ((along == 0 && !seam) || along == n_axis) {
                        state(i, j, k) = WALL;  // on a periodic axis the face at n: a copy
                        continue;
                    }
                    lo[a] = along == 0 ? n_axis - 1 : along - 1;  // across the seam at 0
                    if (is_liquid(phi(i, j, k)) || is_liquid(phi(lo[0], lo[1], lo[2]))) {
                        state(i, j, k) = KNOWN;
                    }
                }
            }
        }
        std::vector<std::size_t> newly_known;
        for (int layer = 0; layer < layers; ++layer) {
            newly_known.clear();
            std::vector<double> values;
            for (int k = 0; k < faces.nk(); ++k) {
                for (int j = 0; j < faces.nj(); ++j) {
                    for (int i = 0; i < faces.ni(); ++i) {
                        if (state(i, j, k) != UNKNOWN) {
                            continue;
                        }
                        double sum = 0.0;
                        int count = 0;
                        const std::array<std::array<int, 3>, 6> neighbours = {{{i - 1, j, k},
                                                                               {i + 1, j, k},
                                                                               {i, j - 1, k},
                                                                               {i, j + 1, k},
                                                                               {i, j, k - 1},
                                                                               {i, j, k + 1}}};
                        for (std::array<int, 3> nb : neighbours) {
                            for (std::size_t b = 0; b < 3; ++b)
                                if (periodic[b])  // cells[b] distinct samples along b
                                    nb[b] = (nb[b] + cells[b]) % cells[b];
                            if (state.contains(nb[0], nb[1], nb[2]) &&
                                state(nb[0], nb[1], nb[2]) == KNOWN) {
                                sum += faces(nb[0], nb[1], nb[2]);
                                ++count;
                            }
                        }
                        if (count > 0) {
                            newly_known.push_back(faces.index(i, j, k));
                            values.push_back(sum / count);
                        }
                    }
                }
            }
            if (newly_known.empty()) {
                break;
            }
            for (std::size_t n = 0; n < newly_known.size(); ++n) {
                faces[newly_known[n]] = values[n];
                state[newly_known[n]] = KNOWN;
            }
        }
        for (std::size_t f = 0; f < faces.size(); ++f) {
            if (state[f] == UNKNOWN) {
                faces[f] = 0.0;
            }
        }
        if (seam)  // the faces at n repeat those at 0
            copy_seam_faces(faces, a);
    }
}

}  // namespace meniscus::fluid
