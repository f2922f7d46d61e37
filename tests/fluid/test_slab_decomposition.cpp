// How the grid's z-layers are split over ranks (issue 40): slabs, ghost layers, owners and the
// blocks cut out of a whole field, wrapped around a periodic z. No MPI.
#include <gtest/gtest.h>

#include <stdexcept>

#include "fluid/grid_block.h"
#include "fluid/halo_exchange.h"
#include "fluid/slab_decomposition.h"

namespace meniscus::fluid {
namespace {

TEST(SlabDecomposition, SplitsTheLayersEvenlyAndOwnsEachOnce) {
    const SlabDecomposition d(11, 3, 2, false);
    EXPECT_EQ(d.owned_begin(0), 0);
    EXPECT_EQ(d.owned_end(0), 4);
    EXPECT_EQ(d.owned_begin(1), 4);
    EXPECT_EQ(d.owned_end(1), 8);
    EXPECT_EQ(d.owned_begin(2), 8);
    EXPECT_EQ(d.owned_end(2), 11);
    // Ghosts clipped at the walls.
    EXPECT_EQ(d.local_begin(0), 0);
    EXPECT_EQ(d.local_end(0), 6);
    EXPECT_EQ(d.local_begin(1), 2);
    EXPECT_EQ(d.local_end(1), 10);
    EXPECT_EQ(d.local_end(2), 11);
    for (int layer = 0; layer < 11; ++layer)
        EXPECT_EQ(d.owner(layer), layer < 4 ? 0 : (layer < 8 ? 1 : 2));
    EXPECT_EQ(d.face_owner(11), 2);  // the top face of a walled grid
    EXPECT_EQ(d.face_owner(4), 1);   // a face belongs to the cell above it
    EXPECT_THROW(d.owner(11), std::out_of_range);
}

TEST(SlabDecomposition, WrapsAroundAPeriodicZ) {
    const SlabDecomposition d(10, 2, 3, true);
    EXPECT_EQ(d.local_begin(0), -3);
    EXPECT_EQ(d.local_end(0), 8);
    EXPECT_EQ(d.local_begin(1), 2);
    EXPECT_EQ(d.local_end(1), 13);
    EXPECT_EQ(d.owner(-1), 1);
    EXPECT_EQ(d.owner(12), 0);
    EXPECT_EQ(d.face_owner(10), 0);  // face nz is face 0
}

TEST(SlabDecomposition, OneRankHasNoGhosts) {
    const SlabDecomposition d(7, 1, 4, true);
    EXPECT_FALSE(d.distributed());
    EXPECT_EQ(d.local_begin(0), 0);
    EXPECT_EQ(d.local_end(0), 7);
    EXPECT_EQ(d.ghost_layers(), 0);
}

TEST(SlabDecomposition, RefusesSlabsThinnerThanTheGhosts) {
    EXPECT_THROW(SlabDecomposition(8, 3, 3, false), std::invalid_argument);
    EXPECT_THROW(SlabDecomposition(2, 3, 0, false), std::invalid_argument);
    EXPECT_THROW(SlabDecomposition(0, 1, 0, false), std::invalid_argument);
    EXPECT_NO_THROW(SlabDecomposition(9, 3, 3, false));
}

TEST(GridBlock, BlocksCarryTheirLayersAndOrigin) {
    MacGrid whole(3, 2, 10, 0.5, Eigen::Vector3d(1.0, 2.0, 3.0));
    whole.set_periodic({true, false, true});
    for (std::size_t e = 0; e < whole.w().size(); ++e)
        whole.w()[e] = static_cast<double>(e);
    const SlabDecomposition d(10, 2, 3, true);
    const MacGrid block = extract_block_grid(whole, d, 0);
    EXPECT_EQ(block.nz(), 11);
    EXPECT_DOUBLE_EQ(block.origin().z(), 3.0 - 1.5);
    EXPECT_TRUE(block.periodic()[0]);
    EXPECT_FALSE(block.periodic()[2]);  // the ghosts hold the other side of the seam
    // Face layer 0 of rank 0's block is face 7 of the whole grid.
    EXPECT_EQ(block.w()(2, 1, 0), whole.w()(2, 1, 7));
    EXPECT_EQ(block.w()(2, 1, 3), whole.w()(2, 1, 0));
    BoundaryOptions walls = BoundaryOptions::all(BoundaryType::no_slip);
    walls.z_max.type = BoundaryType::outflow;
    const SlabDecomposition open(10, 2, 2, false);
    EXPECT_EQ(block_boundaries(walls, open, 0).z_max.type, BoundaryType::free_slip);
    EXPECT_EQ(block_boundaries(walls, open, 0).z_min.type, BoundaryType::no_slip);
    EXPECT_EQ(block_boundaries(walls, open, 1).z_max.type, BoundaryType::outflow);
}

}  // namespace
}  // namespace meniscus::fluid
