#pragma once
/**
 * Sparse voxel octree storage of `vct` (Crassin et al. 2011 §4, notes 001 §2.1-2.3, §2.6-2.7,
 * techniques/vct/svo.md). Node pool of 2x2x2 tiles (one child-tile pointer per node, brick
 * pointer, +-x/y/z neighbour pointers, parent pointer); brick pool of vertex-centred 3x3x3 bricks
 * (opacity + premultiplied radiance, alpha-premultiplied albedo). Leaf bricks sample the
 * voxelizer's N^3 volumes at voxel centres (spacing v0); level l bricks have spacing v0 2^l and are
 * filtered with the 3^3 Gaussian. Empty nodes are collapsed (no children, no brick).
 *
 * Anisotropic (Crassin §9, default in vct): non-leaf nodes store six directional radiance bricks
 * (-X,+X,-Y,+Y,-Z,+Z, rays travelling toward that direction) built by front-to-back pair
 * compositing inside the 3^3 Gaussian; leaves stay isotropic. The radiance pool is indexed by a
 * per-node radiance slot (1 brick, or 6 consecutive bricks for directional nodes); the geometry
 * pool and the flux accumulators by the node's brick index (techniques/vct/svo.md
 * "Anisotropic").
 *
 * Injection as the dense path (techniques/vct/svo.md "Injection"): per light, the photons'
 * irradiance is averaged over the deposits of their footprints in every leaf sample (count pass,
 * then E / count pass), summed over lights; leaf radiance = a albedo / pi E. Facing (Crassin §7):
 * leaves keep the voxelizer's mean normal in a normal brick pool; leaf samples and the first
 * directional level are weighted by common/voxel_facing.glsl.
 *
 * Pools are sized in the constructor from a conservative CPU bound of the occupied leaf cells
 * (triangle / cell overlap on the scene's triangles, dilated by one voxel), so build() and
 * inject() only record into the caller's command buffer.
 */
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <vector>

#include <vulkan/vulkan.h>

#include "core/technique/technique.h"
#include "core/vk/buffer.h"
#include "core/vk/descriptors.h"
#include "core/vk/image.h"
#include "core/vk/pipeline.h"
#include "core/vk/sampler.h"
#include "core/voxel/voxel_grid.h"
#include "core/voxel/voxelizer.h"
#include "photons.h"

namespace gilab::vct {

/** Mirrors SvoInfo in techniques/vct/shaders/svo_common.glsl (uniform buffer, std140). */
struct GpuSvoInfo {
    glm::vec4 originVoxelSize;  // grid minimum corner, w = v0
    glm::uvec4 dims;      // x N, y leaf depth D (root depth 0), z pool bricks along x, w levels
    glm::uvec4 capacity;  // x node capacity, y brick capacity, z float atomics, w bricks along y
    glm::uvec4 radiance;  // x radiance brick capacity, y radiance bricks along x, z along y,
                          // w 1 = anisotropic (non-leaf nodes hold 6 directional bricks)
    glm::uvec4 depthInfo[16];  // per depth d: x occupancy word offset, y cells per axis (2^d),
                               // z bound on the nodes of depth d, w -
};
static_assert(sizeof(GpuSvoInfo) == 320);

class SparseVoxelOctree {
public:
    /** Directional filter of an anisotropic octree (techniques/vct/svo.md "Anisotropic"):
     *  Pairs = the dense rule (front-to-back pairs) on the two pair halves of the 3^3 tent; Slab =
     *  one front-to-back step through the tent's footprint (half-depth end samples). */
    enum class DirectionalFilter : uint32_t { Pairs = 1, Slab = 2 };
    /** `anisotropic`: six directional radiance bricks per non-leaf node (Crassin §9).
     *  `floatAtomics = false` forces the 32-bit fixed-point accumulators (tests). */
    SparseVoxelOctree(TechniqueContext& ctx, const VoxelGrid& grid, bool anisotropic,
                      DirectionalFilter filter = DirectionalFilter::Pairs,
                      bool floatAtomics = true);
    SparseVoxelOctree(const SparseVoxelOctree&) = delete;
    SparseVoxelOctree& operator=(const SparseVoxelOctree&) = delete;

    /** Set-up: nodes + bricks from the voxelizer's volumes (geometry in the leaves, filtered up).
     */
    void build(TechniqueContext& ctx, VkCommandBuffer cmd, VoxelVolumes& voxels);
    /** Per light (photon irradiance.w = light index < lightCount(), each light's photons in one
     *  range of the buffer, as LightInjection writes them): count and irradiance splat into the
     *  leaves; then border transfer, shade, filter up. */
    void inject(TechniqueContext& ctx, VkCommandBuffer cmd, const PhotonSource& photons);
    /** The scene's lights changed (moved, turned, new intensity; same number): recomputes the
     *  light count and the fixed-point irradiance caps from ctx.scene, and rebinds the photon
     *  buffer on the next inject(). Call before re-injecting (VctTechnique::update). inject()
     *  clears the irradiance accumulators and rewrites every leaf and inner radiance brick, so
     *  nothing of the previous injection remains. */
    void updateLights(TechniqueContext& ctx);
    /** Bindings first .. first+3: tree info (uniform buffer), node pool (storage buffer),
     *  radiance brick pool, leaf normal brick pool (combined image samplers); see
     *  techniques/vct/shaders/svo_sample.glsl. */
    static void addLayoutBindings(std::vector<VkDescriptorSetLayoutBinding>& out, uint32_t first,
                                  VkShaderStageFlags stages);
    void writeDescriptors(vk::DescriptorSet& set, uint32_t first) const;
    static constexpr uint32_t kBindingCount = 4;

    struct Memory {
        size_t nodeBytes = 0, brickBytes = 0;  // brickBytes = geometry + radiance + normal pools
        size_t geometryBytes = 0, radianceBytes = 0;
        size_t normalBytes = 0;  // leaf mean normals (RGBA8 snorm, geometry pool layout)
        uint32_t nodeCount = 0;
        uint32_t brickCount = 0;     // nodes with a brick (geometry pool, one brick each)
        uint32_t radianceCount = 0;  // radiance pool bricks (6 per non-leaf node if anisotropic)
        size_t total() const { return nodeBytes + brickBytes; }
        /** Not in total(): irradiance accumulators (3 words per brick sample), deposit counts
         *  (1 word per brick sample), light ranges, occupancy pyramid (set-up scratch, 1 bit
         *  per cell), counters and the info block. */
        size_t scratchBytes = 0;
    };
    /** Allocated pools (capacity from the CPU bound): bytes of the node pool and brick pools
     *  (whole pool textures, including the padding of their last row of bricks). */
    Memory memory() const;
    /** Nodes and bricks the GPU build actually allocated (blocking read-back; not inside a
     *  submission). Bytes = used count x bytes per node / brick. */
    Memory usedMemory() const;
    bool anisotropic() const { return m_anisotropic; }
    DirectionalFilter directionalFilter() const { return m_filterMode; }
    static const char* gatherShaderName() { return "vct/svo_gather.comp"; }

    // Introspection for tests and docs.
    static constexpr uint32_t kNodeWords = 12;  // child, brick, parent, nbr[6], cell, depth,
                                                // radiance slot
    static constexpr uint32_t kBrickSamples = 27;
    const VoxelGrid& grid() const { return m_grid; }
    uint32_t leafDepth() const { return m_leafDepth; }
    uint32_t levelCount() const { return m_leafDepth + 1; }
    const GpuSvoInfo& info() const { return m_info; }
    /** Raw node pool (kNodeWords uint per node) and the allocation counters (tests). */
    std::vector<uint32_t> readNodes() const;
    /** Radiance / geometry brick pool texels (RGBA, x fastest; index with poolTexelIndex). */
    std::vector<glm::vec4> readRadianceBricks() const;
    std::vector<glm::vec4> readGeometryBricks() const;
    /** Normal brick pool texels (geometry pool layout; xyz unit mean normal, w its length). */
    std::vector<glm::vec4> readNormalBricks() const;
    /** Geometry pool texel of sample (i,j,k) of brick b (node word 1). */
    glm::uvec3 brickTexel(uint32_t brick, glm::uvec3 sample) const;
    /** Radiance pool texel of sample (i,j,k) of radiance brick `slot` (node word 11, + face
     *  0..5 = -X,+X,-Y,+Y,-Z,+Z for the directional bricks of a non-leaf node). */
    glm::uvec3 radianceTexel(uint32_t slot, glm::uvec3 sample) const;
    /** Index of `texel` in readRadianceBricks() (radiance) or readGeometryBricks(). */
    size_t poolTexelIndex(glm::uvec3 texel, bool radiance) const;

    /**
     * Work groups of a launch of `threads` threads in groups of `groupSize`: 1D while the group
     * count fits `maxX` (maxComputeWorkGroupCount[0]), else a 2D grid x = maxX, y = ceil(groups
     * / maxX) (the shaders rebuild the index, svoThread() in svo_common.glsl; surplus threads
     * fail the shaders' bounds checks). Throws past maxY.
     */
    static glm::uvec3 dispatchGroups(uint64_t threads, uint32_t groupSize, uint32_t maxX,
                                     uint32_t maxY);
    /** Tests: cap the groups per dimension below the device limit to force 2D grids. */
    void setMaxDispatchGroupsForTesting(uint32_t maxX) { m_maxGroups.x = maxX; }
    static constexpr uint32_t kGroupSize = 64;  // SVO_GROUP_SIZE of the shaders

    /** Fixed-point scale (units per W/m^2) of the irradiance accumulators without float
     *  atomics; by default 2^31 units over the sum of the lights' irradiance caps (as the dense
     *  path), or 2^20 without lights. */
    void setFixedPointScale(double unitsPerWm2) { m_fixedScale = unitsPerWm2; }
    bool usesFloatAtomics() const { return m_floatAtomics; }
    /** Lights of the scene (punctual lights and emitter samples, as buildLightViews numbers
     *  them; at least 1): inject() splats light indices 0 .. lightCount() - 1. */
    uint32_t lightCount() const { return m_lightCount; }
    /** Tests: photons with synthetic light indices. */
    void setLightCountForTesting(uint32_t lights) {
        m_lightCount = std::max(lights, 1u);
        m_irradianceCaps.resize(m_lightCount, 0.0f);
    }
    /** Bytes per node and per brick of one pool (RGBA16F). */
    static constexpr size_t kNodeBytes = kNodeWords * 4;
    static constexpr size_t kBrickBytes = kBrickSamples * 8;
    static constexpr uint32_t kFaces = 6;
    static constexpr size_t kNormalBrickBytes = kBrickSamples * 4;  // RGBA8 snorm
    static constexpr uint32_t kLightWords = 8;  // per light: dispatch x y z, -, first, end, -, -

private:
    void createPipelines();
    void bind(VkCommandBuffer cmd, const vk::ComputePipeline& pipeline, bool voxelSet,
              bool photonSet) const;
    void push(VkCommandBuffer cmd, const glm::uvec4& args, float cap = 0.0f) const;
    void bindAndDispatch(VkCommandBuffer cmd, const vk::ComputePipeline& pipeline,
                         const glm::uvec4& args, uint32_t threads, bool voxelSet,
                         bool photonSet) const;
    void transfer(VkCommandBuffer cmd, uint32_t depth, uint32_t target) const;
    void filterUp(VkCommandBuffer cmd, uint32_t target) const;
    void dispatch(VkCommandBuffer cmd, uint64_t threads) const;

    vk::Context* m_vk = nullptr;
    VoxelGrid m_grid;
    uint32_t m_leafDepth = 0;
    uint32_t m_nodeCapacity = 0, m_brickCapacity = 0, m_radianceCapacity = 0;
    bool m_anisotropic = false;
    DirectionalFilter m_filterMode = DirectionalFilter::Pairs;
    bool m_floatAtomics = false;
    glm::uvec2 m_maxGroups{65535u};
    double m_fixedScale = 1048576.0;
    uint32_t m_lightCount = 1;
    std::vector<float> m_irradianceCaps;  // per light (fixed point: clamp of a photon's E)
    GpuSvoInfo m_info{};
    VkImageView m_voxelView = VK_NULL_HANDLE, m_normalView = VK_NULL_HANDLE;
    VkBuffer m_photonBuffer = VK_NULL_HANDLE;

    vk::Buffer m_infoBuffer;  // GpuSvoInfo (uniform)
    vk::Buffer m_nodes;       // node pool, kNodeWords uint per node
    vk::Buffer m_counters;    // [0] nodes allocated, [1] bricks allocated, [2] overflow flag
    vk::Buffer m_accum;       // irradiance per brick sample (3 words, float or fixed)
    vk::Buffer m_count;       // deposits of the light being splatted per brick sample
    vk::Buffer m_lights;      // kLightWords per light: indirect dispatch, photon range
    vk::Buffer m_occupancy;   // set-up scratch: occupancy pyramid, one bit per cell
    vk::Image m_radiance;     // radiance pool: rgb premultiplied radiance, a opacity
    vk::Image m_geometry;     // brick pool: rgb alpha * albedo, a opacity
    vk::Image m_normals;      // leaf normal bricks (geometry layout): xyz mean normal, w length
    vk::Sampler m_sampler;

    vk::DescriptorSetLayout m_setLayout, m_voxelLayout, m_photonLayout;
    vk::DescriptorSet m_set, m_voxelSet, m_photonSet;
    vk::PipelineLayout m_layout;
    vk::ComputePipeline m_occupancyLeaf, m_occupancyUp, m_buildLevel, m_neighbours, m_leafGeometry,
        m_splat, m_transfer, m_shade, m_filter, m_filterAniso, m_lightRanges;
};

}  // namespace gilab::vct
