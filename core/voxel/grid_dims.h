#pragma once
/** Dimensions of a dense 3D voxel grid on the CPU (binary masks, distance fields, skeletons). */
#include <cstddef>
#include <cstdint>

namespace gilab {

/** x fastest: index = x + nx * (y + ny * z). */
struct GridDims {
    uint32_t nx = 0, ny = 0, nz = 0;

    size_t count() const { return size_t(nx) * ny * nz; }
    size_t index(uint32_t x, uint32_t y, uint32_t z) const {
        return x + size_t(nx) * (y + size_t(ny) * z);
    }
};

}  // namespace gilab
