// The sparse voxel octree of `vct` (techniques/vct/svo.h, techniques/vct/svo.md) on hand-built
// scenes with known answers: node counts, collapsed empty space, brick-border transfer, the 3^3
// Gaussian, the cone sampler, anisotropic (directional) bricks, split dispatches. Gpu* tests run
// with validation on and fail on any message; Cpu* tests need no device.
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include <glm/glm.hpp>
#include "tests/gpu_test_fixture.h"

#include "core/gpu/gpu_scene.h"
#include "core/image/image.h"
#include "core/params/params.h"
#include "core/passes/shared_passes.h"
#include "core/scene/mesh_builder.h"
#include "core/scene/scene.h"
#include "core/scene/scene_loader.h"
#include "core/technique/frame_harness.h"
#include "core/technique/registry.h"
#include "core/technique/technique.h"
#include "core/util/error.h"
#include "core/vk/barrier.h"
#include "core/vk/buffer.h"
#include "core/vk/context.h"
#include "core/vk/descriptors.h"
#include "core/vk/pipeline.h"
#include "core/vk/timer.h"
#include "core/voxel/voxel_grid.h"
#include "core/voxel/voxel_radiance.h"
#include "core/voxel/voxelizer.h"
#include "techniques/vct/light_injection.h"
#include "techniques/vct/photons.h"
#include "techniques/vct/svo.h"
#include "techniques/vct/vct.h"

namespace gilab {
namespace {

using vct::GpuPhoton;
using vct::SparseVoxelOctree;
using Filter = SparseVoxelOctree::DirectionalFilter;
constexpr uint32_t kNone = 0xFFFFFFFFu;
constexpr float kPi = 3.14159265358979f;

Scene boxScene(glm::vec3 albedo, float lo, float hi) {
    Scene s;
    s.name = "svo_test";
    s.sourcePath = "<test>";
    Material m;
    m.baseColorFactor = glm::vec4(albedo, 1.0f);
    s.materials.push_back(m);
    const glm::vec3 a(lo), b(hi);
    appendQuad(s, {a.x, a.y, a.z}, {a.x, b.y, a.z}, {a.x, b.y, b.z}, {a.x, a.y, b.z}, {-1, 0, 0},
               0);
    appendQuad(s, {b.x, a.y, a.z}, {b.x, b.y, a.z}, {b.x, b.y, b.z}, {b.x, a.y, b.z}, {1, 0, 0}, 0);
    appendQuad(s, {a.x, a.y, a.z}, {b.x, a.y, a.z}, {b.x, a.y, b.z}, {a.x, a.y, b.z}, {0, -1, 0},
               0);
    appendQuad(s, {a.x, b.y, a.z}, {b.x, b.y, a.z}, {b.x, b.y, b.z}, {a.x, b.y, b.z}, {0, 1, 0}, 0);
    appendQuad(s, {a.x, a.y, a.z}, {b.x, a.y, a.z}, {b.x, b.y, a.z}, {a.x, b.y, a.z}, {0, 0, -1},
               0);
    appendQuad(s, {a.x, a.y, b.z}, {b.x, a.y, b.z}, {b.x, b.y, b.z}, {a.x, b.y, b.z}, {0, 0, 1}, 0);
    s.computeCaps();
    return s;
}

/** CPU view of the read-back node pool. */
struct Tree {
    std::vector<uint32_t> w;
    uint32_t leafDepth = 0;
    uint32_t word(uint32_t node, uint32_t k) const { return w[node * 12 + k]; }
    /** Node of `cell` at `depth`, or kNone. */
    uint32_t find(glm::ivec3 cell, uint32_t depth) const {
        uint32_t node = 0;
        for (uint32_t k = 0; k < depth; ++k) {
            const uint32_t child = word(node, 0);
            if (child == 0) return kNone;
            const glm::ivec3 o = (cell >> int(depth - k - 1)) & 1;
            node = child + uint32_t(o.x + 2 * o.y + 4 * o.z);
        }
        return node;
    }
};

class GpuVctSvoTest : public test::ValidatedGpuTest {
protected:
    void TearDown() override {
        m_svo.reset();
        m_photons = vk::Buffer();
        m_voxelizer.reset();
        m_tctx.reset();
        m_shared.reset();
        m_gpuScene.reset();
        test::ValidatedGpuTest::TearDown();
    }
    /** Voxelizes `scene` into a 32^3 grid of unit voxels at the origin and builds the octree.
     *  maxGroups > 0: caps the work groups per dispatch dimension (forces 2D grids). */
    void build(const Scene& scene, uint32_t n = 32, bool anisotropic = false,
               uint32_t maxGroups = 0, Filter filter = Filter::Pairs) {
        buildInGrid(scene, VoxelGrid::fromCube(glm::vec3(0.0f), float(n), n), anisotropic,
                    maxGroups, filter);
    }
    void buildInGrid(const Scene& scene, const VoxelGrid& grid, bool anisotropic,
                     uint32_t maxGroups = 0, Filter filter = Filter::Pairs) {
        m_svo.reset();
        m_voxelizer.reset();
        m_tctx.reset();
        m_shared.reset();
        m_gpuScene.reset();
        m_scene = scene;
        m_gpuScene = std::make_unique<vk::GpuScene>(*m_ctx, m_scene);
        m_shared = std::make_unique<SharedPasses>(*m_ctx, *m_gpuScene, 32, 32);
        m_tctx = std::make_unique<TechniqueContext>(
            TechniqueContext{*m_ctx, m_scene, *m_gpuScene, *m_shared, m_params});
        m_tctx->techniqueId = "vct";
        m_grid = grid;
        m_voxelizer = std::make_unique<Voxelizer>(*m_ctx, *m_gpuScene, m_grid);
        m_voxelizer->run();
        m_svo = std::make_unique<SparseVoxelOctree>(*m_tctx, m_grid, anisotropic, filter,
                                                    !m_fixedPoint);
        if (maxGroups > 0) m_svo->setMaxDispatchGroupsForTesting(maxGroups);
        m_tctx->submitTimed(
            [&](VkCommandBuffer cmd) { m_svo->build(*m_tctx, cmd, m_voxelizer->volumes()); });
        m_tree.w = m_svo->readNodes();
        m_tree.leafDepth = m_svo->leafDepth();
    }
    /** Injects one photon (light 0) at the centre of each of `voxels`, carrying irradiance
     *  `irradiance` (W/m^2) on a surface of normal `normal` lit along it, with a footprint of
     *  0.01 v0 (flux = E x 1e-4 v0^2): each deposits into its own voxel only, whose leaf sample
     *  then holds a albedo / pi E (techniques/vct/svo.md "Injection"). */
    void inject(const std::vector<glm::ivec3>& voxels, glm::vec3 irradiance,
                glm::vec3 normal = glm::vec3(0.0f, 0.0f, 1.0f)) {
        const float v0 = m_grid.voxelSize();
        std::vector<GpuPhoton> photons;
        for (const glm::ivec3& v : voxels) {
            GpuPhoton p;
            p.positionValid = glm::vec4(m_grid.voxelCenter(v), 1.0f);
            p.flux = glm::vec4(irradiance * (1e-4f * v0 * v0), 0.0f);
            p.toLight = glm::vec4(normal, 0.0f);
            p.irradiance = glm::vec4(irradiance, 0.0f);
            p.normal = glm::vec4(normal, 1.0f);
            photons.push_back(p);
        }
        injectPhotons(photons);
    }
    void injectPhotons(const std::vector<GpuPhoton>& photons) {
        m_photons =
            vk::Buffer(*m_ctx, photons.size() * sizeof(GpuPhoton),
                       VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, vk::MemoryUsage::Upload, "test/photons");
        m_photons.uploadVector(photons);
        vct::PhotonSource src{&m_photons, uint32_t(photons.size())};
        m_tctx->submitTimed([&](VkCommandBuffer cmd) { m_svo->inject(*m_tctx, cmd, src); });
        m_radiance = m_svo->readRadianceBricks();
    }
    /** voxelConeSample(q.xyz, lod q.w, dir) of every query on the GPU (svo_test_sample.comp). */
    std::vector<glm::vec4> sample(const std::vector<glm::vec4>& queries, glm::vec3 dir) {
        std::vector<glm::vec4> packed;
        for (const glm::vec4& x : queries) {
            packed.push_back(x);
            packed.push_back(glm::vec4(dir, 0.0f));
        }
        return runQueries(packed);
    }
    /** traceCone(origin, dir, tanHalf) of every (origin, dir) pair (step 0.5, no lift). */
    std::vector<glm::vec4> trace(const std::vector<std::pair<glm::vec3, glm::vec3>>& cones,
                                 float tanHalf) {
        std::vector<glm::vec4> packed;
        for (const auto& [origin, dir] : cones) {
            packed.push_back(glm::vec4(origin, 0.0f));
            packed.push_back(glm::vec4(dir, tanHalf));
        }
        return runQueries(packed);
    }
    /** svo_test_sample.comp on queries packed as (position, direction) pairs. */
    std::vector<glm::vec4> runQueries(const std::vector<glm::vec4>& packed) {
        const size_t count = packed.size() / 2;
        vk::Buffer q(*m_ctx, packed.size() * 16, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT,
                     vk::MemoryUsage::Upload, "test/queries");
        q.uploadVector(packed);
        vk::Buffer r(*m_ctx, count * 16, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT,
                     vk::MemoryUsage::Readback, "test/results");
        std::vector<VkDescriptorSetLayoutBinding> b;
        SparseVoxelOctree::addLayoutBindings(b, 0, VK_SHADER_STAGE_COMPUTE_BIT);
        std::vector<vk::DescriptorBinding> bindings;
        for (const auto& x : b)
            bindings.push_back({x.binding, x.descriptorType, 1, x.stageFlags});
        vk::DescriptorSetLayout l0(*m_ctx, bindings, "test/svo");
        vk::DescriptorSetLayout l1(
            *m_ctx,
            {{0, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, VK_SHADER_STAGE_COMPUTE_BIT},
             {1, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, VK_SHADER_STAGE_COMPUTE_BIT}},
            "test/io");
        vk::DescriptorSet s0(*m_ctx, l0), s1(*m_ctx, l1);
        m_svo->writeDescriptors(s0, 0);
        s1.writeBuffer(0, q);
        s1.writeBuffer(1, r);
        vk::PipelineLayout layout(*m_ctx, {l0.handle(), l1.handle()}, 4,
                                  VK_SHADER_STAGE_COMPUTE_BIT);
        vk::ComputePipeline pipe(*m_ctx, "vct/svo_test_sample.comp", layout);
        m_ctx->submitAndWait([&](VkCommandBuffer cmd) {
            pipe.bind(cmd);
            VkDescriptorSet sets[2] = {s0.handle(), s1.handle()};
            vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, layout.handle(), 0, 2,
                                    sets, 0, nullptr);
            layout.push(cmd, uint32_t(count));
            vk::dispatch1D(cmd, uint32_t(count));
            vk::hostReadBarrier(cmd);
        });
        return r.downloadVector<glm::vec4>(count);
    }
    /** Every copy of level-`level` lattice sample `s` in the bricks of `pool` (radiance: the
     *  radiance pool at slot + face; else the geometry pool). */
    std::vector<glm::vec4> copies(const std::vector<glm::vec4>& pool, glm::ivec3 s, uint32_t level,
                                  bool radiance = true, uint32_t face = 0) const {
        std::vector<glm::vec4> out;
        const uint32_t depth = m_tree.leafDepth - level;
        const int cells = 1 << depth;
        for (int k = 0; k < 8; ++k) {
            glm::ivec3 cell = s / 2;
            bool ok = true;
            for (int ax = 0; ax < 3; ++ax)
                if ((k >> ax) & 1) {
                    if (s[ax] % 2 != 0) ok = false;
                    cell[ax] -= 1;
                }
            if (!ok || glm::any(glm::lessThan(cell, glm::ivec3(0))) ||
                glm::any(glm::greaterThanEqual(cell, glm::ivec3(cells))))
                continue;
            const uint32_t node = m_tree.find(cell, depth);
            if (node == kNone) continue;
            const uint32_t brick = m_tree.word(node, radiance ? 11 : 1);
            if (brick == kNone) continue;
            const glm::uvec3 local(s - 2 * cell);
            const glm::uvec3 t = radiance ? m_svo->radianceTexel(brick + face, local)
                                          : m_svo->brickTexel(brick, local);
            out.push_back(pool[m_svo->poolTexelIndex(t, radiance)]);
        }
        return out;
    }

    Scene m_scene;
    ParamSet m_params;
    VoxelGrid m_grid;
    std::unique_ptr<vk::GpuScene> m_gpuScene;
    std::unique_ptr<SharedPasses> m_shared;
    std::unique_ptr<TechniqueContext> m_tctx;
    std::unique_ptr<Voxelizer> m_voxelizer;
    std::unique_ptr<SparseVoxelOctree> m_svo;
    vk::Buffer m_photons;
    Tree m_tree;
    std::vector<glm::vec4> m_radiance;
    bool m_fixedPoint = false;  // build() / buildInGrid(): fixed-point accumulators
};

// Box faces through voxel centres 10 and 21: the voxelizer's shell is voxels 10..21 (known).
constexpr float kLo = 10.5f, kHi = 21.5f;
const glm::vec3 kAlbedo(0.5f, 0.25f, 1.0f);
// Octree vs dense agreement (measured values in techniques/vct/svo.md "Agreement"): both
// inject the per-light mean photon irradiance and weight radiance by the voxels' facing; they
// differ in the filtered levels (3^3 Gaussian vs cell pyramid) and sample positions. Before the
// octree got the irradiance injection and facing: relMSE 0.121, mean abs 0.245, ratio 1.006
// (isotropic) and 0.177, 0.350, 0.940 (anisotropic).
// Issue 43: the bounds were 4x the measured agreement, so they could not catch a change of it.
// Measured again on lavapipe (the image is deterministic): isotropic relMSE 0.0342, mean abs
// 0.203, ratio 0.850 (1.066 at 8e5c056); anisotropic (octree_filter = slab) 0.0309, 0.168,
// 1.026. Bounds: 1.5x the measured errors, the ratio within 0.06 of the measured one.
constexpr double kAgreementRelMse = 0.05;
constexpr double kAgreementMeanAbs = 0.30;
constexpr double kAgreementMeanRatio = 0.85;
constexpr double kAnisoAgreementRelMse = 0.047;
constexpr double kAnisoAgreementMeanAbs = 0.25;
constexpr double kAnisoAgreementMeanRatio = 1.026;
constexpr double kAgreementRatioTolerance = 0.06;

TEST_F(GpuVctSvoTest, LeafNodesAreTheOccupiedLeafCells) {
    build(boxScene(kAlbedo, kLo, kHi));
    const VoxelData vox = m_voxelizer->readVoxels();
    const int cells = 16;
    size_t expected = 0, wrong = 0;
    for (int z = 0; z < cells; ++z)
        for (int y = 0; y < cells; ++y)
            for (int x = 0; x < cells; ++x) {
                bool occ = false;
                for (int k = 0; k < 27; ++k) {
                    const glm::ivec3 v =
                        2 * glm::ivec3(x, y, z) + glm::ivec3(k % 3, k / 3 % 3, k / 9);
                    if (glm::all(glm::lessThan(v, glm::ivec3(32))))
                        occ = occ || vox.albedoOpacity[vox.index(v)].w > 0.0f;
                }
                const uint32_t node = m_tree.find({x, y, z}, m_tree.leafDepth);
                const bool has = node != kNone && m_tree.word(node, 1) != kNone;
                expected += occ ? 1 : 0;
                wrong += occ != has ? 1 : 0;
            }
    size_t leafBricks = 0;
    const SparseVoxelOctree::Memory used = m_svo->usedMemory();
    for (uint32_t i = 0; i < used.nodeCount; ++i)
        leafBricks += (m_tree.word(i, 10) == m_tree.leafDepth && m_tree.word(i, 1) != kNone);
    const SparseVoxelOctree::Memory cap = m_svo->memory();
    std::printf(
        "[svo] box: %zu occupied leaf cells, %zu leaf bricks, nodes %u / %u, bricks %u / %u\n",
        expected, leafBricks, used.nodeCount, cap.nodeCount, used.brickCount, cap.brickCount);
    EXPECT_EQ(wrong, 0u);
    EXPECT_EQ(leafBricks, expected);
    // Shell voxels 10..21: leaf cells 4..10 per axis touch it, minus the inner 6..9 (voxels
    // 12..20, strictly inside).
    EXPECT_EQ(expected, size_t(7 * 7 * 7 - 4 * 4 * 4));
    EXPECT_LE(used.nodeCount, cap.nodeCount);
    EXPECT_LE(used.brickCount, cap.brickCount);
    EXPECT_EQ(used.brickCount, cap.brickCount);  // axis-aligned box: the CPU bound is exact
}

TEST_F(GpuVctSvoTest, EmptySpaceHasNoNodes) {
    build(boxScene(kAlbedo, kLo, kHi));
    // Inside the box (voxels 12..18) and outside it (voxels < 9 or > 22) nothing is stored.
    for (glm::ivec3 cell : {glm::ivec3(7, 7, 7), glm::ivec3(0, 0, 0), glm::ivec3(15, 15, 15),
                            glm::ivec3(2, 12, 8), glm::ivec3(14, 3, 7)}) {
        const uint32_t node = m_tree.find(cell, m_tree.leafDepth);
        EXPECT_TRUE(node == kNone || m_tree.word(node, 1) == kNone)
            << cell.x << "," << cell.y << "," << cell.z;
    }
    // The depth-1 octant x < 16, y < 16, z < 16 holds the box corner; a full tree would have
    // 8^4 = 4096 leaves; the octree stores only the shell's.
    const SparseVoxelOctree::Memory used = m_svo->usedMemory();
    EXPECT_LT(used.nodeCount, 4096u / 4);
    // Neighbour pointers agree with a descent from the root.
    for (uint32_t i = 1; i < used.nodeCount; ++i) {
        const uint32_t p = m_tree.word(i, 9);
        const glm::ivec3 c(p & 1023u, (p >> 10) & 1023u, (p >> 20) & 1023u);
        const uint32_t d = m_tree.word(i, 10);
        ASSERT_EQ(m_tree.find(c, d), i);
        for (int j = 0; j < 6; ++j) {
            glm::ivec3 q = c;
            q[j / 2] += (j % 2) ? 1 : -1;
            const bool inside = glm::all(glm::greaterThanEqual(q, glm::ivec3(0))) &&
                                glm::all(glm::lessThan(q, glm::ivec3(1 << d)));
            EXPECT_EQ(m_tree.word(i, 3 + j), inside ? m_tree.find(q, d) : kNone);
        }
    }
}

TEST_F(GpuVctSvoTest, SharedSampleHoldsOneValueAfterTransfer) {
    build(boxScene(kAlbedo, kLo, kHi));
    // Voxel (12, 14, 10) lies on the z = 10 face; all coordinates even: it is a corner of 8 leaf
    // bricks. The splat adds to one copy; the transfer must make all 8 agree.
    const glm::ivec3 s(12, 14, 10);
    const glm::vec3 flux(2.0f, 1.0f, 0.5f);
    inject({s}, flux);
    const std::vector<glm::vec4> c = copies(m_radiance, s, 0);
    ASSERT_EQ(c.size(), 8u);
    const glm::vec3 expected = kAlbedo / kPi * flux;  // v0 = 1
    for (const glm::vec4& v : c) {
        EXPECT_NEAR(glm::length(glm::vec3(v) - expected), 0.0f, 2e-3f);
        EXPECT_NEAR(v.w, 1.0f, 1e-3f);
    }
    // Its neighbours along x hold no light.
    for (const glm::vec4& v : copies(m_radiance, s + glm::ivec3(1, 0, 0), 0))
        EXPECT_EQ(glm::vec3(v), glm::vec3(0.0f));
}

TEST_F(GpuVctSvoTest, GaussianOfAnImpulseHasTheTentWeights) {
    build(boxScene(kAlbedo, kLo, kHi));
    // Four photons on the shell with 0, 1, 2 and 3 odd coordinates: each is an impulse V at one
    // leaf sample; level-1 samples get V (1/2)^(3-k) (1/4)^k from it (notes 001 §2.3).
    const glm::vec3 flux(64.0f * kPi);  // V = albedo * 64
    const std::vector<glm::ivec3> photons = {
        {12, 14, 10}, {16, 19, 10}, {10, 13, 15}, {21, 13, 17}};
    inject(photons, flux);
    const glm::vec3 v = kAlbedo * 64.0f;
    size_t checked = 0;
    for (const glm::ivec3& s : photons) {
        int odd = 0;
        for (int ax = 0; ax < 3; ++ax)
            odd += s[ax] & 1;
        const float w = std::pow(0.5f, float(3 - odd)) * std::pow(0.25f, float(odd));
        // Level-1 samples p with |2p - s| <= 1 per axis.
        for (int k = 0; k < 8; ++k) {
            glm::ivec3 p = s / 2;
            bool ok = true;
            for (int ax = 0; ax < 3; ++ax)
                if ((k >> ax) & 1) {
                    if (!(s[ax] & 1)) ok = false;
                    p[ax] += 1;
                }
            if (!ok) continue;
            const std::vector<glm::vec4> c = copies(m_radiance, p, 1);
            ASSERT_FALSE(c.empty());
            for (const glm::vec4& x : c) {
                EXPECT_NEAR(x.r, v.r * w, 2e-3f * v.r * w) << s.x << s.y << s.z << " w " << w;
                EXPECT_NEAR(x.b, v.b * w, 2e-3f * v.b * w);
            }
            ++checked;
        }
    }
    EXPECT_EQ(checked, size_t(1 + 2 + 4 + 8));
    // Geometry opacity of a level-1 sample in the middle of a face: the face layer is one of
    // three child layers along its normal: 1/2 of the weight (1/4, 1/2, 1/4 with the face at the
    // centre) -> alpha = 1/2.
    const std::vector<glm::vec4> geo = m_svo->readGeometryBricks();
    for (const glm::vec4& g : copies(geo, glm::ivec3(8, 8, 5), 1, false))
        EXPECT_NEAR(g.a, 0.5f, 1e-3f);
}

TEST_F(GpuVctSvoTest, ConeSamplerIsQuadrilinear) {
    build(boxScene(kAlbedo, kLo, kHi));
    const glm::ivec3 s(12, 14, 10);
    inject({s}, glm::vec3(64.0f * kPi));
    const glm::vec3 v = kAlbedo * 64.0f;
    // Queries: (world position, lod).
    const glm::vec3 at = m_grid.voxelCenter(s);
    std::vector<glm::vec4> queries = {
        glm::vec4(at, 0.0f),                                // the sample: V
        glm::vec4(at + glm::vec3(0.5f, 0, 0), 0.0f),        // half way to an empty neighbour: V/2
        glm::vec4(at, 1.0f),                                // level-1 sample 2p = s: V/8
        glm::vec4(at, 0.5f),                                // between: (V + V/8) / 2
        glm::vec4(m_grid.voxelCenter({16, 16, 16}), 0.0f),  // inside the box: empty
        glm::vec4(m_grid.voxelCenter({16, 16, 16}), 2.7f),  // coarse: some opacity
        glm::vec4(-1.0f, 5.0f, 5.0f, 0.0f),                 // outside the grid
    };
    const std::vector<glm::vec4> out = sample(queries, glm::vec3(0.0f, 0.0f, 1.0f));
    const float tol = 0.01f;  // hardware filtering (8-bit sub-texel weights) and RGBA16F
    EXPECT_NEAR(out[0].r, v.r, tol * v.r);
    EXPECT_NEAR(out[0].a, 1.0f, tol);
    EXPECT_NEAR(out[1].r, 0.5f * v.r, tol * v.r);
    EXPECT_NEAR(out[2].r, v.r / 8.0f, tol * v.r / 8.0f);
    EXPECT_NEAR(out[3].r, 0.5f * (v.r + v.r / 8.0f), tol * v.r);
    EXPECT_EQ(out[4], glm::vec4(0.0f));
    EXPECT_GT(out[5].a, 0.0f);
    EXPECT_LT(out[5].a, 1.0f);
    EXPECT_EQ(out[6], glm::vec4(0.0f));
    for (const glm::vec4& x : out)
        for (int k = 0; k < 4; ++k)
            EXPECT_TRUE(std::isfinite(x[k]));
}

/** The indirect layer of vct on the Cornell box spot variant at 64x64 with `storage`. */
Image vctIndirect(vk::Context& ctx, const std::string& storage, uint32_t voxels, bool anisotropic,
                  std::vector<std::string>* notes = nullptr) {
    Scene scene = loadSceneFile(std::string(GILAB_SOURCE_DIR) + "/scenes/cornell_box.json", "spot");
    scene.settings.width = 64;
    scene.settings.height = 64;
    ParamSet params = TechniqueRegistry::instance().defaultParams("vct");
    params.set("storage", storage);
    params.set("voxel_resolution", std::to_string(voxels));
    params.set("anisotropic", anisotropic ? "true" : "false");
    FrameHarness h(ctx, scene, "vct", params, defaultSharedParams());
    EXPECT_TRUE(h.support().supported) << h.support().reason;
    h.setup();
    h.renderFrame();
    if (notes) *notes = h.notes();
    for (ImageLayer& l : h.readLayers())
        if (l.name == "indirect") return std::move(l.image);
    throw Error("no indirect layer");
}

struct Agreement {
    double relMse = 0, relMeanAbs = 0, meanRatio = 0;
};

/** Octree vs dense indirect layers of vct on cornell_box.json#spot, 64x64, 64^3. */
Agreement octreeVsDense(vk::Context& ctx, bool anisotropic) {
    std::vector<std::string> notes;
    const Image dense = vctIndirect(ctx, "dense", 64, anisotropic);
    const Image octree = vctIndirect(ctx, "octree", 64, anisotropic, &notes);
    EXPECT_EQ(dense.values().size(), octree.values().size());
    const int c = dense.channels();
    double se = 0, ref2 = 0, absDiff = 0, refSum = 0, octSum = 0;
    for (size_t i = 0; i < std::min(dense.values().size(), octree.values().size()); ++i) {
        if (c == 4 && i % 4 == 3) continue;
        const double a = octree.values()[i], b = dense.values()[i];
        EXPECT_TRUE(std::isfinite(a));
        se += (a - b) * (a - b);
        ref2 += b * b;
        absDiff += std::abs(a - b);
        refSum += b;
        octSum += a;
    }
    EXPECT_GT(refSum, 0.0);
    Agreement r;
    r.relMse = se / std::max(ref2, 1e-30);
    r.relMeanAbs = absDiff / std::max(refSum, 1e-30);
    r.meanRatio = octSum / std::max(refSum, 1e-30);
    std::printf(
        "[svo] cornell#spot 64x64, 64^3, %s: relMSE %.4f, mean |diff| / mean %.4f, mean "
        "octree / dense %.4f\n",
        anisotropic ? "anisotropic" : "isotropic", r.relMse, r.relMeanAbs, r.meanRatio);
    for (const std::string& note : notes)
        std::printf("[svo]   note: %s\n", note.c_str());
    return r;
}

// Same image within a documented tolerance (techniques/vct/svo.md "Agreement with the dense
// variant"): the two storages differ by design in their filtered levels (vertex-centred 3^3
// Gaussian vs the dense cell-centred pyramid), their sample positions at coarse levels and their
// edge handling.
TEST_F(GpuVctSvoTest, OctreeAndDenseGiveTheSameIndirectLight) {
    const Agreement a = octreeVsDense(*m_ctx, false);
    EXPECT_LT(a.relMse, kAgreementRelMse);
    EXPECT_LT(a.relMeanAbs, kAgreementMeanAbs);
    EXPECT_NEAR(a.meanRatio, kAgreementMeanRatio, kAgreementRatioTolerance);
}

// Both anisotropic (vct's default): the octree's directional bricks vs the dense directional
// volumes (techniques/vct/svo.md "Anisotropic").
TEST_F(GpuVctSvoTest, AnisotropicOctreeAndDenseGiveTheSameIndirectLight) {
    const Agreement a = octreeVsDense(*m_ctx, true);
    EXPECT_LT(a.relMse, kAnisoAgreementRelMse);
    EXPECT_LT(a.relMeanAbs, kAnisoAgreementMeanAbs);
    EXPECT_NEAR(a.meanRatio, kAnisoAgreementMeanRatio, kAgreementRatioTolerance);
}

/** A one-voxel wall: the plane x = layer + 0.5 (voxel layer 16) across the whole 32^3 grid,
 *  facing `nx` along x. */
Scene wallScene(int layer = 16, float nx = 1.0f) {
    Scene s;
    s.name = "svo_wall";
    s.sourcePath = "<test>";
    Material m;
    m.baseColorFactor = glm::vec4(kAlbedo, 1.0f);
    s.materials.push_back(m);
    const float x = float(layer) + 0.5f;
    appendQuad(s, {x, 0, 0}, {x, 32, 0}, {x, 32, 32}, {x, 0, 32}, {nx, 0, 0}, 0);
    s.computeCaps();
    return s;
}

// Crassin §9: a wall one voxel thick keeps opacity 1 along its normal at every level of the
// anisotropic octree, while the isotropic Gaussian halves it per level (2^-l). Along the wall
// (tangent) the directional value is the dense rule's 1/2 at the first level, then
// t' = (1 - (1 - t)^2) / 2 (two half-covered layers composited, then half the tent): it stays
// low. The wall's layer 16 = 2^4 lies on a parent's centre sample at every level
// (techniques/vct/svo.md "Anisotropic": a wall on an odd child sample keeps 1/2 at the next
// level).
TEST_F(GpuVctSvoTest, AnisotropicWallIsOpaqueAlongItsNormal) {
    for (int mode : {0, 1, 2}) {  // isotropic, pairs, slab
        const bool aniso = mode != 0;
        build(wallScene(), 32, aniso, 0, mode == 2 ? Filter::Slab : Filter::Pairs);
        inject({{16, 16, 16}}, glm::vec3(kPi));
        ASSERT_EQ(m_tree.leafDepth, 4u);
        float tangent = 0.5f;
        for (uint32_t level = 1; level <= m_tree.leafDepth; ++level) {
            const glm::ivec3 s(16 >> level);  // the wall's centre sample at this level
            SCOPED_TRACE("level " + std::to_string(level) + " mode " + std::to_string(mode));
            if (!aniso) {
                const std::vector<glm::vec4> c = copies(m_radiance, s, level);
                ASSERT_FALSE(c.empty());
                for (const glm::vec4& v : c)
                    EXPECT_NEAR(v.a, std::ldexp(1.0f, -int(level)), 2e-3f);
                continue;
            }
            for (uint32_t f = 0; f < 6; ++f) {
                const std::vector<glm::vec4> c = copies(m_radiance, s, level, true, f);
                ASSERT_FALSE(c.empty());
                for (const glm::vec4& v : c) {
                    if (f < 2)
                        EXPECT_NEAR(v.a, 1.0f, 2e-3f) << "face " << f;
                    else
                        EXPECT_NEAR(v.a, tangent, 3e-3f) << "face " << f;
                }
            }
            // Off the wall (one level-l sample away along x): nothing along the normal either.
            for (uint32_t f = 0; f < 2; ++f)
                for (const glm::vec4& v :
                     copies(m_radiance, s + glm::ivec3(1, 0, 0), level, true, f))
                    EXPECT_NEAR(v.a, 0.0f, 1e-3f);
            tangent = 0.5f * (1.0f - (1.0f - tangent) * (1.0f - tangent));
        }
        // The sampler: dir^2-weighted faces (normal: 1, tangent: <= 1/2, isotropic: 2^-l).
        const glm::vec3 at = m_grid.voxelCenter({16, 16, 16});
        std::vector<glm::vec4> q;
        for (float lod : {1.0f, 2.0f, 3.0f, 0.5f, 2.5f})
            q.push_back(glm::vec4(at, lod));
        const std::vector<glm::vec4> nx = sample(q, glm::vec3(-1, 0, 0));
        const std::vector<glm::vec4> px = sample(q, glm::vec3(1, 0, 0));
        const std::vector<glm::vec4> py = sample(q, glm::vec3(0, 1, 0));
        const std::vector<glm::vec4> diag = sample(q, glm::normalize(glm::vec3(1, 1, 0)));
        // Tangent opacity per level: the leaves are isotropic (1), then 1/2, 3/8, ...
        std::vector<float> tangentAt = {1.0f, 0.5f};
        while (tangentAt.size() < 5) {
            const float t = tangentAt.back();
            tangentAt.push_back(0.5f * (1.0f - (1.0f - t) * (1.0f - t)));
        }
        for (size_t i = 0; i < q.size(); ++i) {
            const float lod = q[i].w;
            const int l0 = int(std::floor(lod));
            const float f = lod - float(l0);
            auto lerp = [&](float a0, float a1) { return (1.0f - f) * a0 + f * a1; };
            SCOPED_TRACE("lod " + std::to_string(lod) + " mode " + std::to_string(mode));
            if (aniso) {
                EXPECT_NEAR(nx[i].a, 1.0f, 0.01f);
                EXPECT_NEAR(px[i].a, 1.0f, 0.01f);
                EXPECT_NEAR(py[i].a, lerp(tangentAt[l0], tangentAt[l0 + 1]), 0.01f);
                if (lod >= 1.0f) {
                    EXPECT_LE(py[i].a, 0.5f + 0.01f);
                }
                EXPECT_NEAR(diag[i].a, 0.5f * (px[i].a + py[i].a), 0.01f);
            } else {
                const float expected = lerp(std::exp2(-float(l0)), std::exp2(-float(l0 + 1)));
                EXPECT_NEAR(nx[i].a, expected, 0.01f);
                EXPECT_NEAR(py[i].a, expected, 0.01f);
            }
        }
    }
}

// A wall on an odd leaf sample (voxel layer 17) falls between two level-1 samples. The pair
// filter gives each 1/2 along the normal (one of its two pairs holds the wall); the slab filter
// integrates the wall's half depth into both: 1 (techniques/vct/svo.md "Anisotropic").
TEST_F(GpuVctSvoTest, OddWallKeepsHalfWithPairsAndAllWithSlabs) {
    for (Filter filter : {Filter::Pairs, Filter::Slab}) {
        SCOPED_TRACE(filter == Filter::Slab ? "slab" : "pairs");
        build(wallScene(17), 32, true, 0, filter);
        inject({{17, 16, 16}}, glm::vec3(kPi));
        const float expected = filter == Filter::Slab ? 1.0f : 0.5f;
        for (int x : {8, 9})
            for (uint32_t f = 0; f < 2; ++f)
                for (const glm::vec4& v : copies(m_radiance, {x, 8, 8}, 1, true, f))
                    EXPECT_NEAR(v.a, expected, 2e-3f) << "x " << x << " face " << f;
        for (uint32_t f = 0; f < 2; ++f)
            for (const glm::vec4& v : copies(m_radiance, {7, 8, 8}, 1, true, f))
                EXPECT_NEAR(v.a, 0.0f, 1e-3f);
    }
}

/** common/voxel_facing.glsl on the CPU: weight of a voxel of mean normal m (xyz * length) seen
 *  by rays travelling along unit `dir`. */
float cpuFacing(glm::vec3 m, glm::vec3 dir) {
    float len = glm::length(m);
    if (!(len > 1e-4f)) return 1.0f;
    const float front = glm::clamp(0.5f - 2.0f * glm::dot(m, dir) / len, 0.0f, 1.0f);
    len = std::min(len, 1.0f);
    return glm::mix((1.0f - len) / (1.0f + len), 1.0f, front);
}

/** CPU directional filter on the global level lattice (no partial sums, no transfer). */
glm::vec4 cpuComposite(glm::vec4 front, glm::vec4 back) {
    return front + (1.0f - glm::clamp(front.a, 0.0f, 1.0f)) * back;
}
glm::vec4 cpuHalfSlab(glm::vec4 v) {
    const float a = glm::clamp(v.a, 0.0f, 1.0f);
    if (!(a > 1e-6f)) return 0.5f * v;
    const float h = a >= 1.0f ? 1.0f : 1.0f - std::sqrt(1.0f - a);
    return glm::vec4(glm::vec3(v) * (h / a), h);
}

// The GPU's directional bricks (per-parent partial sums + add/copy transfer, neighbour reads for
// the slab filter) equal a direct evaluation of the filter on the global lattice of the level
// below, for every sample, face and copy of levels 1 and 2 (box shell on even and odd layers;
// level 1 composites the leaves' colours weighted by their facing toward the face's direction).
TEST_F(GpuVctSvoTest, DirectionalBricksMatchACpuFilter) {
    for (Filter filter : {Filter::Pairs, Filter::Slab}) {
        SCOPED_TRACE(filter == Filter::Slab ? "slab" : "pairs");
        build(boxScene(kAlbedo, kLo, kHi), 32, true, 0, filter);
        std::vector<glm::ivec3> photons;
        for (int a = 10; a <= 21; ++a)
            for (int b = 10; b <= 21; b += 1) {
                photons.push_back({a, b, 10});  // z = 10 face (even layer)
                photons.push_back({21, a, b});  // x = 21 face (odd layer)
                if ((a + b) % 3 == 0) photons.push_back({a, 21, b});
            }
        inject(photons, glm::vec3(8.0f * kPi));
        const std::vector<glm::vec4> normals = m_svo->readNormalBricks();
        size_t checked = 0, nonzero = 0;
        for (uint32_t level = 1; level <= 2; ++level) {
            const int below = 32 >> (level - 1);  // samples 0 .. below at the level below
            for (uint32_t f = 0; f < 6; ++f) {
                const int axis = int(f / 2);
                const bool towardPositive = (f & 1) != 0;
                glm::vec3 travel(0.0f);
                travel[axis] = towardPositive ? 1.0f : -1.0f;
                // The level below (leaves: isotropic, colour facing-weighted; else face f), one
                // copy per sample.
                auto at = [&](glm::ivec3 c) {
                    if (glm::any(glm::lessThan(c, glm::ivec3(0))) ||
                        glm::any(glm::greaterThan(c, glm::ivec3(below))))
                        return glm::vec4(0.0f);
                    const std::vector<glm::vec4> v =
                        copies(m_radiance, c, level - 1, true, level == 1 ? 0 : f);
                    if (v.empty()) return glm::vec4(0.0f);
                    glm::vec4 x = glm::max(v[0], glm::vec4(0.0f));
                    if (level == 1) {
                        const glm::vec4 nl = copies(normals, c, 0, false)[0];
                        const float w =
                            cpuFacing(glm::vec3(nl) * glm::clamp(nl.w, 0.0f, 1.0f), travel);
                        x = glm::vec4(glm::vec3(x) * w, x.a);
                    }
                    return x;
                };
                const int n = below / 2;
                for (int z = 0; z <= n; ++z)
                    for (int y = 0; y <= n; ++y)
                        for (int x = 0; x <= n; ++x) {
                            const glm::ivec3 p(x, y, z);
                            glm::vec4 expected(0.0f);
                            const int au = (axis + 1) % 3, av = (axis + 2) % 3;
                            for (int du = -1; du <= 1; ++du)
                                for (int dv = -1; dv <= 1; ++dv) {
                                    const float w =
                                        (du == 0 ? 0.5f : 0.25f) * (dv == 0 ? 0.5f : 0.25f);
                                    glm::ivec3 c = 2 * p;
                                    c[au] += du;
                                    c[av] += dv;
                                    glm::ivec3 lo = c, hi = c;
                                    lo[axis] -= 1;
                                    hi[axis] += 1;
                                    glm::vec4 l = at(lo), m = at(c), h = at(hi);
                                    if (!towardPositive) std::swap(l, h);
                                    if (filter == Filter::Slab)
                                        expected +=
                                            w * cpuComposite(cpuHalfSlab(l),
                                                             cpuComposite(m, cpuHalfSlab(h)));
                                    else
                                        expected +=
                                            0.5f * w * (cpuComposite(l, m) + cpuComposite(m, h));
                                }
                            const std::vector<glm::vec4> got =
                                copies(m_radiance, p, level, true, f);
                            if (got.empty()) {
                                EXPECT_LT(glm::length(expected), 1e-4f) << p.x << p.y << p.z;
                                continue;
                            }
                            nonzero += expected.a > 0.0f;
                            for (const glm::vec4& g : got) {
                                const float tol = 4e-3f * (1.0f + glm::length(expected));
                                EXPECT_NEAR(glm::length(g - expected), 0.0f, tol)
                                    << "level " << level << " face " << f << " sample " << p.x
                                    << "," << p.y << "," << p.z << " got " << g.r << " " << g.a
                                    << " expected " << expected.r << " " << expected.a;
                                ++checked;
                            }
                        }
            }
        }
        std::printf("[svo] %s: %zu directional samples checked (%zu with opacity)\n",
                    filter == Filter::Slab ? "slab" : "pairs", checked, nonzero);
        EXPECT_GT(nonzero, 500u);
    }
}

// Face convention (as the dense volumes, docs/voxel_cone_tracing.md): face +X holds what rays
// travelling toward +x see, so they meet the smaller-x layer first. A red layer (voxels x = 16)
// in front of a green one (x = 17): +X sees red only, -X sees green, at every level. Both layers
// are two-sided (a quad each way: mean normal 0, so facing leaves them isotropic).
TEST_F(GpuVctSvoTest, AnisotropicFacesSeeTheNearLayerFirst) {
    Scene s;
    s.name = "svo_layers";
    s.sourcePath = "<test>";
    for (glm::vec3 albedo : {glm::vec3(1, 0, 0), glm::vec3(0, 1, 0)}) {
        Material m;
        m.baseColorFactor = glm::vec4(albedo, 1.0f);
        s.materials.push_back(m);
    }
    for (uint32_t k = 0; k < 2; ++k) {
        const float x = 16.5f + float(k);
        appendQuad(s, {x, 0, 0}, {x, 32, 0}, {x, 32, 32}, {x, 0, 32}, {1, 0, 0}, k);
        appendQuad(s, {x, 0, 0}, {x, 0, 32}, {x, 32, 32}, {x, 32, 0}, {-1, 0, 0}, k);
    }
    s.computeCaps();
    build(s, 32, true);
    for (const glm::vec4& nl : copies(m_svo->readNormalBricks(), {16, 16, 16}, 0, false))
        ASSERT_LT(nl.w, 0.05f);
    std::vector<glm::ivec3> photons;
    for (int x = 16; x <= 17; ++x)
        for (int z = 8; z <= 24; ++z)  // the level-3 tent around voxel 16 reaches 9 .. 23
            for (int y = 8; y <= 24; ++y)
                photons.push_back({x, y, z});
    inject(photons, glm::vec3(kPi));
    for (uint32_t level = 1; level <= 3; ++level) {
        SCOPED_TRACE("level " + std::to_string(level));
        const glm::ivec3 at(16 >> level);
        const std::vector<glm::vec4> towardPosX = copies(m_radiance, at, level, true, 1);
        const std::vector<glm::vec4> towardNegX = copies(m_radiance, at, level, true, 0);
        ASSERT_FALSE(towardPosX.empty());
        for (const glm::vec4& v : towardPosX) {
            EXPECT_NEAR(v.a, 1.0f, 2e-3f);
            EXPECT_GT(v.r, 0.5f);
            EXPECT_LT(v.g, 1e-3f * v.r);
        }
        for (const glm::vec4& v : towardNegX) {
            EXPECT_NEAR(v.a, 1.0f, 2e-3f);
            EXPECT_GT(v.g, 0.2f * v.r);
        }
    }
}

// The radiance pool of the anisotropic octree holds one brick per leaf and six per inner node;
// reported next to the isotropic one (techniques/vct/svo.md "Memory"; Crassin §9 quotes
// ~1.5x).
TEST_F(GpuVctSvoTest, AnisotropicMemoryIsAboutOneAndAHalfIsotropic) {
    Scene scene = loadSceneFile(std::string(GILAB_SOURCE_DIR) + "/scenes/cornell_box.json", "spot");
    const VoxelGrid grid(scene.caps.bounds, 64);
    std::map<bool, SparseVoxelOctree::Memory> used, cap;
    for (bool aniso : {false, true}) {
        buildInGrid(scene, grid, aniso);
        used[aniso] = m_svo->usedMemory();
        cap[aniso] = m_svo->memory();
        uint32_t leaves = 0;
        for (uint32_t i = 0; i < used[aniso].nodeCount; ++i)
            leaves += m_tree.word(i, 10) == m_tree.leafDepth && m_tree.word(i, 1) != kNone;
        const uint32_t inner = used[aniso].brickCount - leaves;
        EXPECT_EQ(used[aniso].radianceCount, aniso ? leaves + 6 * inner : leaves + inner);
        EXPECT_LE(used[aniso].radianceCount, cap[aniso].radianceCount);
        std::printf(
            "[svo] cornell 64^3 %s: nodes %u, bricks %u (%u leaves), radiance bricks %u; used "
            "%.2f MiB (nodes %.2f, geometry %.2f, radiance %.2f), allocated %.2f MiB\n",
            aniso ? "anisotropic" : "isotropic", used[aniso].nodeCount, used[aniso].brickCount,
            leaves, used[aniso].radianceCount, used[aniso].total() / 1048576.0,
            used[aniso].nodeBytes / 1048576.0, used[aniso].geometryBytes / 1048576.0,
            used[aniso].radianceBytes / 1048576.0, cap[aniso].total() / 1048576.0);
    }
    EXPECT_EQ(used[false].brickCount, used[true].brickCount);
    EXPECT_EQ(used[false].nodeCount, used[true].nodeCount);
    const double ratio = double(used[true].total()) / double(used[false].total());
    const double radianceRatio =
        double(used[true].radianceBytes) / double(used[false].radianceBytes);
    std::printf("[svo] anisotropic / isotropic octree: total %.3f, radiance pool %.3f\n", ratio,
                radianceRatio);
    EXPECT_GT(ratio, 1.3);
    EXPECT_LT(ratio, 1.8);
    EXPECT_NEAR(double(cap[true].total()) / double(cap[false].total()), ratio, 0.1);
}

// Every octree dispatch as a 2D grid (at most 5 groups per row: 64^3 leaf occupancy, filters and
// transfers all split, with surplus threads) builds the same octree as 1D dispatches: the shaders
// rebuild the thread index from both dimensions.
TEST_F(GpuVctSvoTest, SplitDispatchesBuildTheSameOctree) {
    const std::vector<glm::ivec3> photons = {{12, 14, 10}, {16, 19, 10}, {10, 13, 15}};
    std::map<uint32_t, std::vector<glm::vec4>> radiance, geometry;
    std::map<uint32_t, Tree> trees;
    for (uint32_t maxGroups : {0u, 5u}) {
        build(boxScene(kAlbedo, kLo, kHi), 32, true, maxGroups, Filter::Slab);
        inject(photons, glm::vec3(64.0f * kPi));
        radiance[maxGroups] = m_radiance;
        geometry[maxGroups] = m_svo->readGeometryBricks();
        trees[maxGroups] = m_tree;
    }
    // Compare by cell (allocation order may differ): every sample of every level and face.
    size_t compared = 0, lit = 0;
    for (uint32_t level = 0; level <= m_tree.leafDepth; ++level) {
        const int samples = 2 * (1 << (m_tree.leafDepth - level)) + 1;
        for (int z = 0; z < samples; ++z)
            for (int y = 0; y < samples; ++y)
                for (int x = 0; x < samples; ++x) {
                    for (uint32_t f = 0; f < (level == 0 ? 1u : 6u); ++f) {
                        m_tree = trees[0];
                        const auto a = copies(radiance[0], {x, y, z}, level, true, f);
                        const auto ga = copies(geometry[0], {x, y, z}, level, false);
                        m_tree = trees[5];
                        const auto b = copies(radiance[5], {x, y, z}, level, true, f);
                        const auto gb = copies(geometry[5], {x, y, z}, level, false);
                        ASSERT_EQ(a.size(), b.size());
                        ASSERT_EQ(ga.size(), gb.size());
                        for (size_t i = 0; i < a.size(); ++i) {
                            EXPECT_NEAR(glm::length(a[i] - b[i]), 0.0f,
                                        1e-3f * (1.0f + glm::length(a[i])));
                            EXPECT_NEAR(glm::length(ga[i] - gb[i]), 0.0f, 1e-3f);
                            lit += a[i].r > 0.0f;
                        }
                        compared += a.size();
                    }
                }
    }
    std::printf("[svo] split dispatches: %zu brick samples compared, %zu lit\n", compared, lit);
    EXPECT_GT(compared, 1000u);
    EXPECT_GT(lit, 10u);
}

/** A square plane of side 2 centred at the origin, its normal tilted by `tiltDeg` from +y about
 *  z (as techniques/vct/tests/vct_injection_test.cpp), with a small quad below it that moves the
 * grid (centred on the scene bounds) off the plane, lit by `lights`. */
struct TiltedPlane {
    float size = 2.0f;
    glm::vec3 n{0.0f, 1.0f, 0.0f}, u{1.0f, 0.0f, 0.0f}, w{0.0f, 0.0f, 1.0f};
    explicit TiltedPlane(float tiltDeg) {
        const float t = glm::radians(tiltDeg);
        n = glm::vec3(-std::sin(t), std::cos(t), 0.0f);
        u = glm::vec3(std::cos(t), std::sin(t), 0.0f);
    }
    Scene scene(const std::vector<Light>& lights) const {
        Scene s;
        s.name = "svo_injection_plane";
        s.sourcePath = "<test>";
        Material m;
        m.baseColorFactor = glm::vec4(kAlbedo, 1.0f);
        s.materials.push_back(m);
        const float h = 0.5f * size;
        appendQuad(s, -h * u - h * w, h * u - h * w, h * u + h * w, -h * u + h * w, n, 0);
        const glm::vec3 c(h * std::abs(u.x) + 0.1f, -h * std::abs(u.y) - 0.15f, 0.05f);
        const float q = 0.02f;
        appendQuad(s, c - q * u - q * w, c + q * u - q * w, c + q * u + q * w, c - q * u + q * w, n,
                   0);
        s.lights = lights;
        s.camera.position = 3.0f * n;
        s.camera.target = glm::vec3(0.0f);
        s.camera.up = u;
        s.computeCaps();
        return s;
    }
};

struct PlaneAgreement {
    size_t voxels = 0, samples = 0;  // covered voxels compared, brick copies compared
    double meanRatio = 0.0;          // leaf radiance / (a albedo / pi E), mean over copies
    double maxRelError = 0.0;        // over copies and channels
};

class GpuVctSvoInjection : public GpuVctSvoTest {
protected:
    /** vct's light injection (LightInjection photons, octree splat) on the plane at 32^3; every
     *  brick copy of every covered voxel whose centre projects 2 voxels inside the plane's edges
     *  is compared with a albedo / pi E(projection). */
    PlaneAgreement run(const TiltedPlane& plane, const std::vector<Light>& lights,
                       const std::function<glm::dvec3(glm::vec3)>& irradiance) {
        const Scene scene = plane.scene(lights);
        buildInGrid(scene, VoxelGrid(scene.caps.bounds, 32), true);
        vct::LightInjection injection(*m_tctx, m_grid, 0, true);
        EXPECT_EQ(m_svo->lightCount(), injection.lightCount());
        m_tctx->submitTimed([&](VkCommandBuffer cmd) {
            injection.recordPhotons(*m_tctx, cmd);
            m_svo->inject(*m_tctx, cmd, injection.photons());
        });
        m_radiance = m_svo->readRadianceBricks();
        const std::vector<glm::vec4> geometry = m_svo->readGeometryBricks();
        const VoxelData vox = m_voxelizer->readVoxels();
        const float v0 = m_grid.voxelSize();
        const int n = int(m_grid.resolution());
        PlaneAgreement a;
        double sum = 0.0;
        for (int z = 0; z < n; ++z)
            for (int y = 0; y < n; ++y)
                for (int x = 0; x < n; ++x) {
                    const glm::ivec3 v(x, y, z);
                    if (vox.albedoOpacity[vox.index(v)].w <= 0.0f) continue;
                    const glm::vec3 c = m_grid.voxelCenter(v);
                    if (std::abs(glm::dot(plane.n, c)) > 2.0f * v0) continue;  // the small quad
                    const glm::vec3 p = c - plane.n * glm::dot(plane.n, c);
                    const float limit = 0.5f * plane.size - 2.0f * v0;
                    if (std::abs(glm::dot(p, plane.u)) > limit ||
                        std::abs(glm::dot(p, plane.w)) > limit)
                        continue;
                    const glm::dvec3 e = irradiance(p);
                    const std::vector<glm::vec4> got = copies(m_radiance, v, 0);
                    const std::vector<glm::vec4> geo = copies(geometry, v, 0, false);
                    EXPECT_EQ(got.size(), geo.size());
                    for (size_t i = 0; i < std::min(got.size(), geo.size()); ++i) {
                        for (int k = 0; k < 3; ++k) {
                            const double expected = double(geo[i][k]) / kPi * e[k];  // a albedo
                            const double r = double(got[i][k]) / expected;
                            a.maxRelError = std::max(a.maxRelError, std::abs(r - 1.0));
                            if (k == 0) sum += r;
                        }
                        ++a.samples;
                    }
                    ++a.voxels;
                }
        if (a.samples > 0) a.meanRatio = sum / double(a.samples);
        return a;
    }
};

// techniques/vct/svo.md "Injection": the dense path's per-light mean irradiance on the octree
// leaves is exact for a plane at any tilt (before: sum of flux / v0^2 into the photon's voxel, 0.73
// at 30 deg and 0.71 at 45 deg on average, as the dense path's old normalisation).
TEST_F(GpuVctSvoInjection, PlaneUnderDirectionalLightIsExactAtAnyTilt) {
    for (float tilt : {0.0f, 30.0f, 45.0f}) {
        const TiltedPlane plane(tilt);
        Light light;
        light.type = LightType::Directional;
        light.direction = glm::normalize(glm::vec3(0.2f, -1.0f, 0.3f));
        light.intensity = glm::vec3(2.0f, 1.0f, 0.5f);
        light.color = light.intensity;
        const double cosTheta = -glm::dot(plane.n, light.direction);
        const PlaneAgreement a =
            run(plane, {light}, [&](glm::vec3) { return glm::dvec3(light.intensity) * cosTheta; });
        std::printf(
            "[svo] directional, tilt %2.0f deg: %zu voxels (%zu brick copies), leaf radiance / "
            "(a albedo/pi E) mean %.5f, max rel error %.2e\n",
            tilt, a.voxels, a.samples, a.meanRatio, a.maxRelError);
        ASSERT_GT(a.voxels, 200u);
        EXPECT_NEAR(a.meanRatio, 1.0, 0.002) << "tilt " << tilt;
        EXPECT_LT(a.maxRelError, 0.01) << "tilt " << tilt;
    }
}

// The same with the 32-bit fixed-point accumulators (devices without float atomics): 2^31 units
// over the sum of the lights' irradiance caps.
TEST_F(GpuVctSvoInjection, FixedPointAccumulatorsGiveTheSameIrradiance) {
    m_fixedPoint = true;
    const TiltedPlane plane(30.0f);
    Light light;
    light.type = LightType::Directional;
    light.direction = glm::normalize(glm::vec3(0.2f, -1.0f, 0.3f));
    light.intensity = glm::vec3(2.0f, 1.0f, 0.5f);
    light.color = light.intensity;
    const double cosTheta = -glm::dot(plane.n, light.direction);
    const PlaneAgreement a =
        run(plane, {light}, [&](glm::vec3) { return glm::dvec3(light.intensity) * cosTheta; });
    std::printf(
        "[svo] fixed point, directional, tilt 30 deg: %zu voxels, mean %.5f, max rel "
        "error %.2e\n",
        a.voxels, a.meanRatio, a.maxRelError);
    EXPECT_FALSE(m_svo->usesFloatAtomics());
    ASSERT_GT(a.voxels, 200u);
    EXPECT_NEAR(a.meanRatio, 1.0, 0.002);
    EXPECT_LT(a.maxRelError, 0.01);
}

// A point light 1.5 m along the plane's normal (the footprint from flux / E of pinhole texels)
// and two directional lights at once (each light's mean, summed).
TEST_F(GpuVctSvoInjection, PointAndTwoLightsMatchTheAnalyticIrradiance) {
    for (float tilt : {0.0f, 45.0f}) {
        const TiltedPlane plane(tilt);
        Light point;
        point.type = LightType::Point;
        point.position = 1.5f * plane.n;
        point.intensity = glm::vec3(3.0f, 2.0f, 1.0f);
        point.color = point.intensity;
        const PlaneAgreement a = run(plane, {point}, [&](glm::vec3 p) {
            const glm::dvec3 d = glm::dvec3(point.position) - glm::dvec3(p);
            const double r = glm::length(d);
            return glm::dvec3(point.intensity) * (glm::dot(glm::dvec3(plane.n), d) / (r * r * r));
        });
        std::printf("[svo] point, tilt %2.0f deg: %zu voxels, mean %.5f, max rel error %.2e\n",
                    tilt, a.voxels, a.meanRatio, a.maxRelError);
        ASSERT_GT(a.voxels, 200u);
        EXPECT_NEAR(a.meanRatio, 1.0, 0.005) << "tilt " << tilt;
        EXPECT_LT(a.maxRelError, 0.03) << "tilt " << tilt;

        Light sun1, sun2;
        sun1.type = sun2.type = LightType::Directional;
        sun1.direction = glm::normalize(glm::vec3(0.2f, -1.0f, 0.3f));
        sun1.intensity = glm::vec3(2.0f, 1.0f, 0.5f);
        sun1.color = sun1.intensity;
        sun2.direction = glm::normalize(glm::vec3(-0.6f, -1.0f, -0.2f));
        sun2.intensity = glm::vec3(0.5f, 1.0f, 2.0f);
        sun2.color = sun2.intensity;
        const PlaneAgreement b = run(plane, {sun1, sun2}, [&](glm::vec3) {
            return glm::dvec3(sun1.intensity) * double(-glm::dot(plane.n, sun1.direction)) +
                   glm::dvec3(sun2.intensity) * double(-glm::dot(plane.n, sun2.direction));
        });
        std::printf("[svo] two suns, tilt %2.0f deg: %zu voxels, mean %.5f, max rel error %.2e\n",
                    tilt, b.voxels, b.meanRatio, b.maxRelError);
        ASSERT_GT(b.voxels, 200u);
        EXPECT_EQ(m_svo->lightCount(), 2u);
        EXPECT_NEAR(b.meanRatio, 1.0, 0.002) << "tilt " << tilt;
        EXPECT_LT(b.maxRelError, 0.01) << "tilt " << tilt;
    }
}

// Same photons, same rule: on the Cornell box #spot at 64^3 the octree's leaf samples hold the
// dense base volume's radiance voxel by voxel (techniques/vct/svo.md "Injection"; before the
// port the leaves summed to 0.95 of the base and 870 voxels were lit only in the dense volume). The
// two differ only where the footprint shapes matter (the octree's footprint is a square of the
// texel's area, the dense one the texel's parallelogram): voxels at the edge of the lit region.
TEST_F(GpuVctSvoTest, LeavesHoldTheDenseBaseRadiance) {
    Scene scene = loadSceneFile(std::string(GILAB_SOURCE_DIR) + "/scenes/cornell_box.json", "spot");
    std::vector<glm::vec4> base;
    {
        ParamSet params = TechniqueRegistry::instance().defaultParams("vct");
        params.set("storage", "dense");
        params.set("voxel_resolution", "64");
        vk::GpuScene gpuScene(*m_ctx, scene);
        SharedPasses shared(*m_ctx, gpuScene, 64, 64);
        std::vector<std::string> skipped, notes;
        TechniqueContext ctx{*m_ctx, scene,   gpuScene, shared, params, 64,
                             64,     nullptr, &skipped, &notes, "vct",  nullptr};
        VctTechnique dense;
        dense.setup(ctx);
        base = dense.radiance()->readLevel(0, 0);
    }
    buildInGrid(scene, VoxelGrid(scene.caps.bounds, 64), true);
    vct::LightInjection injection(*m_tctx, m_grid, 0, true);
    m_tctx->submitTimed([&](VkCommandBuffer cmd) {
        injection.recordPhotons(*m_tctx, cmd);
        m_svo->inject(*m_tctx, cmd, injection.photons());
    });
    m_radiance = m_svo->readRadianceBricks();
    const int n = 64;
    ASSERT_EQ(base.size(), size_t(n) * n * n);
    double sumDense = 0.0, sumOctree = 0.0;
    size_t lit = 0, onlyDense = 0, onlyOctree = 0, within1 = 0, within5 = 0, copiesDiffer = 0;
    for (int z = 0; z < n; ++z)
        for (int y = 0; y < n; ++y)
            for (int x = 0; x < n; ++x) {
                const glm::ivec3 v(x, y, z);
                const double d = base[m_grid.linearIndex(v)].r;
                const std::vector<glm::vec4> c = copies(m_radiance, v, 0);
                const double o = c.empty() ? 0.0 : double(c[0].r);
                for (const glm::vec4& k : c)
                    copiesDiffer += std::abs(double(k.r) - o) > 1e-3 * (o + 1e-6);
                sumDense += d;
                sumOctree += o;
                if (d <= 0.0 && o <= 0.0) continue;
                ++lit;
                onlyDense += o <= 0.0;
                onlyOctree += d <= 0.0;
                const double rel = std::abs(o - d) / std::max(d, o);
                within1 += rel < 0.01;
                within5 += rel < 0.05;
            }
    const double ratio = sumOctree / sumDense;
    std::printf(
        "[svo] cornell#spot 64^3 leaves vs dense base (red): sum ratio %.4f; %zu lit voxels, "
        "%.1f %% within 1 %%, %.1f %% within 5 %%; lit only in dense %zu, only in the octree %zu\n",
        ratio, lit, 100.0 * double(within1) / double(lit), 100.0 * double(within5) / double(lit),
        onlyDense, onlyOctree);
    EXPECT_EQ(copiesDiffer, 0u);
    EXPECT_NEAR(ratio, 1.0, 0.01);
    EXPECT_GT(double(within5), 0.95 * double(lit));
    EXPECT_LT(double(onlyDense + onlyOctree), 0.01 * double(lit));
}

// Crassin §7 facing (common/voxel_facing.glsl, techniques/vct/svo.md "Facing"; the octree
// version of GpuVoxelCone.FacingHidesTheBackOfAWall): a lit one-voxel wall at x = 16 facing -x,
// seen from the front (rays toward +x) shines, seen from behind it is black (< 2 %) with the same
// opacity, at the leaf level (samples, a narrow cone) and, anisotropic, at the directional levels
// (a wide cone, samples at lod 0.5 .. 2.5). The isotropic octree weights its leaf samples only.
TEST_F(GpuVctSvoTest, FacingHidesTheBackOfAWall) {
    for (bool aniso : {true, false}) {
        SCOPED_TRACE(aniso ? "anisotropic" : "isotropic");
        build(wallScene(16, -1.0f), 32, aniso);
        std::vector<glm::ivec3> lit;
        for (int z = 0; z < 32; ++z)
            for (int y = 0; y < 32; ++y)
                lit.push_back({16, y, z});
        inject(lit, glm::vec3(kPi), glm::vec3(-1.0f, 0.0f, 0.0f));  // leaf radiance = albedo
        const glm::vec3 wall = m_grid.voxelCenter({16, 16, 16});
        const glm::vec3 front = m_grid.gridToWorld(glm::vec3(6.0f, 16.0f, 16.0f));
        const glm::vec3 back = m_grid.gridToWorld(glm::vec3(27.0f, 16.0f, 16.0f));
        const glm::vec3 px(1, 0, 0), nx(-1, 0, 0);
        std::vector<glm::vec4> fromFront, fromBack;
        for (float tanHalf : {0.05f, 0.3f}) {
            fromFront.push_back(trace({{front, px}}, tanHalf)[0]);
            fromBack.push_back(trace({{back, nx}}, tanHalf)[0]);
        }
        std::vector<glm::vec4> q;
        for (float lod : {0.0f, 0.5f, 1.5f, 2.5f})
            q.push_back(glm::vec4(wall, lod));
        const std::vector<glm::vec4> sf = sample(q, px), sb = sample(q, nx);
        for (size_t i = 0; i < q.size(); ++i) {
            fromFront.push_back(sf[i]);
            fromBack.push_back(sb[i]);
        }
        // Queries: narrow cone, wide cone, lod 0, 0.5, 1.5, 2.5; isotropic: the leaf level only
        // (the narrow cone stays at lod 0 up to the wall, 10.5 voxels away).
        const std::vector<size_t> checked =
            aniso ? std::vector<size_t>{0, 1, 2, 3, 4, 5} : std::vector<size_t>{0, 2};
        for (size_t i : checked) {
            const glm::vec4 f = fromFront[i], b = fromBack[i];
            std::printf("[svo] facing %s query %zu: front %.4f (a %.3f), back %.4f (a %.3f)\n",
                        aniso ? "aniso" : "iso", i, f.r, f.a, b.r, b.a);
            EXPECT_GT(f.a, 0.3f) << i;
            EXPECT_NEAR(f.r / f.a, kAlbedo.r, 0.05f * kAlbedo.r) << i;
            EXPECT_NEAR(b.a, f.a, 0.05f) << i;  // opacity both ways
            EXPECT_LT(b.r, 0.02f * kAlbedo.r) << i;
        }
    }
}

// The group counts of every octree dispatch stay within maxComputeWorkGroupCount; Sponza at
// 256^3 filtered 104,875 groups in x in one dispatch (issue 9, item 6).
TEST(CpuVctSvoDispatch, GroupsStayWithinTheDeviceLimit) {
    const uint32_t maxX = 65535, maxY = 65535, group = SparseVoxelOctree::kGroupSize;
    for (uint64_t threads :
         {uint64_t(0), uint64_t(1), uint64_t(64), uint64_t(65), uint64_t(65535) * 64,
          uint64_t(65535) * 64 + 1, uint64_t(104875) * 64, uint64_t(104875) * 64 - 5,
          uint64_t(256) * 256 * 256, uint64_t(1) << 32}) {
        const glm::uvec3 g = SparseVoxelOctree::dispatchGroups(threads, group, maxX, maxY);
        SCOPED_TRACE(threads);
        EXPECT_LE(g.x, maxX);
        EXPECT_LE(g.y, maxY);
        EXPECT_EQ(g.z, threads == 0 ? 0u : 1u);
        const uint64_t launched = uint64_t(g.x) * g.y * g.z * group;
        EXPECT_GE(launched, threads);
        // Surplus below one row of groups (the shaders' bounds checks drop it).
        EXPECT_LT(launched, threads + uint64_t(std::max(g.x, 1u)) * group);
        if (threads > 0 && threads <= uint64_t(maxX) * group) {
            EXPECT_EQ(g.y, 1u);
        }
    }
    const glm::uvec3 sponza = SparseVoxelOctree::dispatchGroups(104875ull * 64, group, maxX, maxY);
    EXPECT_EQ(sponza, glm::uvec3(65535, 2, 1));
    EXPECT_THROW(
        SparseVoxelOctree::dispatchGroups(uint64_t(maxX) * maxY * group + 1, group, maxX, maxY),
        Error);
}

}  // namespace
}  // namespace gilab
