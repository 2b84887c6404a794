#include "cvgi_readback.h"

#include <string>

#include "core/util/error.h"
#include "core/voxel/voxel_compaction.h"
#include "core/voxel/voxel_fragments.h"

namespace gilab {

cvgi::CompactVoxels readCompactVoxels(const VoxelGrid& grid, VoxelCompaction& compaction,
                                      VoxelFragmentLists& lists, uint32_t fragmentCount) {
    cvgi::CompactVoxels out;
    out.resolution = grid.resolution();
    const uint32_t v = compaction.occupied();
    out.linear = compaction.hashedPosition().downloadVector<uint32_t>(v);
    const std::vector<uint32_t> heads = compaction.fragmentIndex().downloadVector<uint32_t>(v);
    const std::vector<GpuVoxelFragment> fragments = lists.readFragments(fragmentCount);
    out.indexOf.assign(grid.voxelCount(), cvgi::kEmpty);
    out.albedo.resize(v);
    out.meanNormal.resize(v);
    out.fragmentOffset.assign(v + 1, 0);
    out.fragmentNormal.reserve(fragmentCount);
    for (uint32_t i = 0; i < v; ++i) {
        if (i > 0 && out.linear[i] <= out.linear[i - 1])
            throw Error("cvgi: compacted voxels out of order at " + std::to_string(i));
        out.indexOf[out.linear[i]] = i;
        glm::vec3 albedo(0.0f), normal(0.0f);
        uint32_t count = 0;
        for (uint32_t f = heads[i]; f != kVoxelListEnd; f = fragments[f].next) {
            if (f >= fragments.size() || count > fragmentCount)
                throw Error("cvgi: broken fragment list at voxel " + std::to_string(i));
            const glm::vec3 n = fragmentNormal(fragments[f]);
            albedo += fragmentAlbedo(fragments[f]);
            normal += n;
            out.fragmentNormal.push_back(n);
            ++count;
        }
        out.fragmentOffset[i + 1] = uint32_t(out.fragmentNormal.size());
        out.albedo[i] = count > 0 ? albedo / float(count) : glm::vec3(0.0f);
        const float len = glm::length(normal);
        out.meanNormal[i] = len > 1e-3f * float(count) ? normal / len : glm::vec3(0.0f);
    }
    return out;
}

}  // namespace gilab
