// The topology cache (techniques/topovpl/topology_cache.h): exact round trips of a synthetic
// SceneTopology, misses, corrupt files rejected with a reason, and what the key depends on.
// CPU only.
#include <algorithm>
#include <bit>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <optional>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "tests/temp_dir.h"

#include "core/scene/mesh_builder.h"
#include "core/util/error.h"
#include "core/util/hash.h"
#include "techniques/topovpl/nearest_node.h"
#include "techniques/topovpl/topology_cache.h"

namespace gilab {
namespace {
namespace fs = std::filesystem;
using topo::SceneTopology;

constexpr const char* kKey = "0123456789abcdef0123456789abcdef";

/** A T-shaped skeleton (a thin and a wide arm along x, a branch along y) in a 32^3 grid, so the
 *  segmentation has several clusters and gates; voxelCluster a pattern with unlabelled voxels. */
SceneTopology syntheticTopology() {
    SceneTopology t;
    t.grid = VoxelGrid::fromCube({-1.5f, 0.25f, 2.0f}, 3.7f, 32);
    t.dims = {32, 32, 32};
    std::vector<glm::ivec3> voxels;
    std::vector<float> radii;
    for (int x = 3; x <= 28; ++x) {
        voxels.emplace_back(x, 8, 10);
        radii.push_back(x < 14 ? 1.5f : 4.0f);
    }
    for (int y = 9; y <= 28; ++y) {
        voxels.emplace_back(14, y, 10);
        radii.push_back(y < 20 ? 2.0f : 1.0f);
    }
    t.skeletonVoxels = uint32_t(voxels.size());
    t.graph = topo::buildSkeletonGraph(voxels, radii);
    t.graph.prunedNodes = 7;  // any value: it must survive the round trip
    t.segmentation = topo::segmentSkeleton(t.graph, 0.2f);
    const uint32_t clusters = t.segmentation.clusterCount;
    t.voxelCluster.resize(t.dims.count());
    for (size_t i = 0; i < t.voxelCluster.size(); ++i) {
        const uint32_t c = uint32_t(i % (clusters + 1));
        t.voxelCluster[i] = c == clusters ? topo::kNoNode : c;
        t.emptyVoxels += c == clusters ? 0 : 1;
    }
    t.solidVoxels = uint32_t(t.dims.count()) - t.emptyVoxels;
    const float v = t.grid.voxelSize();
    for (const topo::Gate& g : t.segmentation.gates)
        t.gates.push_back({t.grid.gridToWorld(g.centre + 0.5f), g.normal, g.radius * v,
                           g.radiusA * v, g.radiusB * v, g.clusterA, g.clusterB, g.radiusNeck * v});
    return t;
}

std::vector<uint32_t> bits(const std::vector<float>& v) {
    std::vector<uint32_t> out;
    for (float x : v)
        out.push_back(std::bit_cast<uint32_t>(x));
    return out;
}
std::vector<uint32_t> bits(const std::vector<glm::vec3>& v) {
    std::vector<uint32_t> out;
    for (const glm::vec3& x : v)
        for (int k = 0; k < 3; ++k)
            out.push_back(std::bit_cast<uint32_t>(x[k]));
    return out;
}
template <class G>
std::vector<uint32_t> bits(const std::vector<G>& gates) {
    std::vector<uint32_t> out;
    for (const G& g : gates) {
        for (int k = 0; k < 3; ++k)
            out.push_back(std::bit_cast<uint32_t>(g.centre[k]));
        for (int k = 0; k < 3; ++k)
            out.push_back(std::bit_cast<uint32_t>(g.normal[k]));
        out.push_back(std::bit_cast<uint32_t>(g.radiusNeck));
        out.push_back(std::bit_cast<uint32_t>(g.radius));
        out.push_back(std::bit_cast<uint32_t>(g.radiusA));
        out.push_back(std::bit_cast<uint32_t>(g.radiusB));
        out.push_back(g.clusterA);
        out.push_back(g.clusterB);
    }
    return out;
}

void expectSame(const SceneTopology& a, const SceneTopology& b) {
    EXPECT_EQ(bits(std::vector<glm::vec3>{a.grid.origin()}),
              bits(std::vector<glm::vec3>{b.grid.origin()}));
    EXPECT_EQ(std::bit_cast<uint32_t>(a.grid.side()), std::bit_cast<uint32_t>(b.grid.side()));
    EXPECT_EQ(a.grid.resolution(), b.grid.resolution());
    EXPECT_EQ(a.dims.nx, b.dims.nx);
    EXPECT_EQ(a.dims.ny, b.dims.ny);
    EXPECT_EQ(a.dims.nz, b.dims.nz);
    EXPECT_EQ(a.skeletonVoxels, b.skeletonVoxels);
    EXPECT_EQ(a.emptyVoxels, b.emptyVoxels);
    EXPECT_EQ(a.solidVoxels, b.solidVoxels);
    EXPECT_EQ(bits(a.graph.position), bits(b.graph.position));
    EXPECT_EQ(bits(a.graph.maxball), bits(b.graph.maxball));
    EXPECT_EQ(a.graph.adjacency, b.graph.adjacency);
    EXPECT_EQ(a.graph.voxelNode, b.graph.voxelNode);
    EXPECT_EQ(a.graph.prunedNodes, b.graph.prunedNodes);
    const topo::Segmentation &s = a.segmentation, &r = b.segmentation;
    EXPECT_EQ(s.kind, r.kind);
    EXPECT_EQ(s.segmentedNode, r.segmentedNode);
    EXPECT_EQ(s.kept, r.kept);
    EXPECT_EQ(s.segmentedAdjacency, r.segmentedAdjacency);
    EXPECT_EQ(s.cluster, r.cluster);
    EXPECT_EQ(s.clusterCount, r.clusterCount);
    EXPECT_EQ(s.greedyClusters, r.greedyClusters);
    EXPECT_EQ(bits(s.gates), bits(r.gates));
    EXPECT_EQ(s.curvatureNodes, r.curvatureNodes);
    EXPECT_EQ(s.coverageNodes, r.coverageNodes);
    EXPECT_EQ(s.topologyNodes, r.topologyNodes);
    EXPECT_EQ(a.voxelCluster, b.voxelCluster);
    EXPECT_EQ(bits(a.gates), bits(b.gates));
}

std::string readFile(const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}
void writeFile(const fs::path& p, const std::string& bytes) {
    std::ofstream(p, std::ios::binary | std::ios::trunc) << bytes;
}

/** Replaces the 16-byte checksum at the end by the XXH3-128 of the rest (the documented form). */
void resealChecksum(std::string& bytes) {
    const size_t body = bytes.size() - 16;
    const std::string hex = hashHex128(std::string_view(bytes).substr(0, body));
    for (size_t i = 0; i < 16; ++i)
        bytes[body + i] = char(std::stoi(hex.substr(2 * i, 2), nullptr, 16));
}

void putU32(std::string& bytes, size_t at, uint32_t v) {
    for (int i = 0; i < 4; ++i)
        bytes[at + i] = char((v >> (8 * i)) & 0xffu);
}
void putU64(std::string& bytes, size_t at, uint64_t v) {
    for (int i = 0; i < 8; ++i)
        bytes[at + i] = char((v >> (8 * i)) & 0xffu);
}

/** Stores `t`, lets `edit` change the file, then loads it: expects a rejection with a reason. */
template <class Edit>
std::string rejectionOf(const SceneTopology& t, Edit edit) {
    test::TempDir dir("topology_cache");
    topo::storeTopology(dir.path(), kKey, t);
    const fs::path file = topo::topologyCacheFile(dir.path(), kKey);
    std::string bytes = readFile(file);
    edit(bytes);
    writeFile(file, bytes);
    std::string why;
    const std::optional<SceneTopology> loaded = topo::loadTopology(dir.path(), kKey, &why);
    EXPECT_FALSE(loaded.has_value());
    EXPECT_FALSE(why.empty());
    EXPECT_NE(why.find(file.string()), std::string::npos) << why;
    return why;
}

/** Byte offsets of the trailing arrays (see the layout in topology_cache.h). */
struct Tail {
    size_t voxelClusterLength, lastVoxelCluster, worldGatesLength, lastGateClusterB;
};
Tail tailOffsets(const std::string& bytes, const SceneTopology& t) {
    Tail o;
    o.worldGatesLength = bytes.size() - 16 - t.gates.size() * 48 - 8;
    o.lastGateClusterB = bytes.size() - 16 - 4;
    o.voxelClusterLength = o.worldGatesLength - t.voxelCluster.size() * 4 - 8;
    o.lastVoxelCluster = o.worldGatesLength - 4;
    return o;
}

TEST(CpuTopologyCache, SyntheticTopologyIsNotTrivial) {
    const SceneTopology t = syntheticTopology();
    EXPECT_GE(t.segmentation.clusterCount, 2u);
    EXPECT_FALSE(t.segmentation.gates.empty());
    EXPECT_GE(t.segmentation.kept.size(), 3u);
    EXPECT_GT(t.graph.position.size(), t.segmentation.kept.size());
    // Both end radii are kept, and differ on some gate (the thin and the wide arm), so the round
    // trip below tells radiusA from radiusB.
    bool unequal = false;
    for (size_t i = 0; i < t.gates.size(); ++i) {
        const topo::Gate& g = t.segmentation.gates[i];
        EXPECT_EQ(g.radius, std::min(g.radiusA, g.radiusB));
        EXPECT_GT(g.radiusA, 0.0f);
        EXPECT_GT(g.radiusB, 0.0f);
        EXPECT_EQ(t.gates[i].radiusA, g.radiusA * t.grid.voxelSize());
        EXPECT_EQ(t.gates[i].radiusB, g.radiusB * t.grid.voxelSize());
        EXPECT_GT(g.radiusNeck, 0.0f);
        EXPECT_LE(g.radiusNeck, g.radius);
        unequal = unequal || g.radiusA != g.radiusB;
    }
    EXPECT_TRUE(unequal);
    EXPECT_EQ(t.segmentation.greedyClusters, t.segmentation.clusterCount);  // no merge here
}

TEST(CpuTopologyCache, StoreAndLoadRoundTripEveryField) {
    test::TempDir dir("topology_cache");
    const SceneTopology t = syntheticTopology();
    topo::storeTopology(dir.path(), kKey, t);
    EXPECT_TRUE(fs::is_regular_file(dir.path() / (std::string(kKey) + ".topo")));
    std::string why = "stale";
    const std::optional<SceneTopology> loaded = topo::loadTopology(dir.path(), kKey, &why);
    ASSERT_TRUE(loaded.has_value()) << why;
    EXPECT_TRUE(why.empty());
    expectSame(t, *loaded);
    // Only the entry remains: no temporary file.
    EXPECT_EQ(std::distance(fs::directory_iterator(dir.path()), fs::directory_iterator()), 1);
}

TEST(CpuTopologyCache, EmptyTopologyRoundTrips) {
    test::TempDir dir("topology_cache");
    SceneTopology t;
    t.grid = VoxelGrid::fromCube(glm::vec3(0.0f), 1.0f, 32);
    t.dims = {32, 32, 32};
    t.voxelCluster.assign(t.dims.count(), topo::kNoNode);
    t.solidVoxels = uint32_t(t.dims.count());
    topo::storeTopology(dir.path(), kKey, t);
    std::string why;
    const std::optional<SceneTopology> loaded = topo::loadTopology(dir.path(), kKey, &why);
    ASSERT_TRUE(loaded.has_value()) << why;
    expectSame(t, *loaded);
}

TEST(CpuTopologyCache, StoreReplacesAnEntry) {
    test::TempDir dir("topology_cache");
    SceneTopology t = syntheticTopology();
    topo::storeTopology(dir.path(), kKey, t);
    t.graph.prunedNodes = 99;
    t.gates.front().radiusA = 0.25f;
    t.gates.front().radiusB = 0.125f;
    t.gates.front().radius = 0.125f;
    t.gates.front().radiusNeck = 0.0625f;
    topo::storeTopology(dir.path(), kKey, t);
    const std::optional<SceneTopology> loaded = topo::loadTopology(dir.path(), kKey);
    ASSERT_TRUE(loaded.has_value());
    expectSame(t, *loaded);
}

TEST(CpuTopologyCache, MissingKeyIsAMissWithoutReason) {
    test::TempDir dir("topology_cache");
    std::string why = "stale";
    EXPECT_FALSE(topo::loadTopology(dir.path(), kKey, &why).has_value());
    EXPECT_TRUE(why.empty());
    EXPECT_FALSE(topo::loadTopology(dir.path() / "absent_folder", kKey, &why).has_value());
    EXPECT_TRUE(why.empty());
    EXPECT_FALSE(topo::loadTopology(dir.path(), kKey).has_value());  // why is optional
}

TEST(CpuTopologyCache, TruncatedFileIsRejected) {
    const SceneTopology t = syntheticTopology();
    test::TempDir dir("topology_cache");
    topo::storeTopology(dir.path(), kKey, t);
    const fs::path file = topo::topologyCacheFile(dir.path(), kKey);
    const std::string full = readFile(file);
    for (size_t size : {size_t(0), size_t(5), size_t(8), size_t(30), size_t(200), full.size() / 2,
                        full.size() - 17, full.size() - 1}) {
        writeFile(file, full.substr(0, size));
        std::string why;
        EXPECT_FALSE(topo::loadTopology(dir.path(), kKey, &why).has_value()) << size;
        EXPECT_FALSE(why.empty()) << size;
    }
    writeFile(file, full + "x");  // one byte too many
    std::string why;
    EXPECT_FALSE(topo::loadTopology(dir.path(), kKey, &why).has_value());
    EXPECT_NE(why.find("after the checksum"), std::string::npos) << why;
}

TEST(CpuTopologyCache, FlippedMagicByteIsRejected) {
    const std::string why =
        rejectionOf(syntheticTopology(), [](std::string& bytes) { bytes[3] ^= 0x20; });
    EXPECT_NE(why.find("magic"), std::string::npos) << why;
}

TEST(CpuTopologyCache, OtherVersionIsRejected) {
    const std::string why =
        rejectionOf(syntheticTopology(), [](std::string& bytes) { putU32(bytes, 8, 1000); });
    EXPECT_NE(why.find("format version 1000"), std::string::npos) << why;
}

TEST(CpuTopologyCache, CorruptedLengthIsRejected) {
    const SceneTopology t = syntheticTopology();
    // A length far beyond the file: rejected before anything is allocated.
    std::string why = rejectionOf(t, [&](std::string& bytes) {
        putU64(bytes, tailOffsets(bytes, t).voxelClusterLength, uint64_t(1) << 60);
    });
    EXPECT_NE(why.find("length of voxelCluster"), std::string::npos) << why;
    // One element short: the rest of the file is read out of step.
    why = rejectionOf(t, [&](std::string& bytes) {
        putU64(bytes, tailOffsets(bytes, t).voxelClusterLength, t.voxelCluster.size() - 1);
    });
    EXPECT_FALSE(why.empty());
    // The first array's length (graph.position, right after the header and the anchored count).
    why = rejectionOf(t, [&](std::string& bytes) {
        const size_t at = 8 + 4 + 4 + 4 + 32 + 5 * 4 + 3 * 4 + 3 * 4 + 8;
        putU64(bytes, at, ~uint64_t(0));
    });
    EXPECT_NE(why.find("graph.position"), std::string::npos) << why;
}

TEST(CpuTopologyCache, ChecksumMismatchIsRejected) {
    const SceneTopology t = syntheticTopology();
    const std::string why = rejectionOf(
        t, [&](std::string& bytes) { bytes[tailOffsets(bytes, t).lastVoxelCluster] ^= 1; });
    EXPECT_NE(why.find("checksum"), std::string::npos) << why;
}

TEST(CpuTopologyCache, InconsistentContentIsRejected) {
    const SceneTopology t = syntheticTopology();
    // Cluster ids out of range, in a file whose lengths and checksum are right.
    std::string why = rejectionOf(t, [&](std::string& bytes) {
        putU32(bytes, tailOffsets(bytes, t).lastGateClusterB, 1000);
        resealChecksum(bytes);
    });
    EXPECT_NE(why.find("gates["), std::string::npos) << why;
    why = rejectionOf(t, [&](std::string& bytes) {
        putU32(bytes, tailOffsets(bytes, t).lastVoxelCluster, t.segmentation.clusterCount);
        resealChecksum(bytes);
    });
    EXPECT_NE(why.find("voxelCluster["), std::string::npos) << why;
    // A world gate whose radius is not the minimum of its end radii (the last gate's radiusB,
    // 8 bytes before its clusterB, set to half its radius).
    why = rejectionOf(t, [&](std::string& bytes) {
        const size_t at = tailOffsets(bytes, t).lastGateClusterB - 8;
        putU32(bytes, at, std::bit_cast<uint32_t>(t.gates.back().radius * 0.5f));
        resealChecksum(bytes);
    });
    EXPECT_NE(why.find("end radii"), std::string::npos) << why;
    // Another entry's file under this key.
    why = rejectionOf(t, [&](std::string& bytes) {
        bytes[20] = bytes[20] == 'f' ? 'e' : 'f';
        resealChecksum(bytes);
    });
    EXPECT_NE(why.find("holds key"), std::string::npos) << why;
}

TEST(CpuTopologyCache, StoreRefusesInconsistentTopologiesAndBadKeys) {
    test::TempDir dir("topology_cache");
    const SceneTopology good = syntheticTopology();
    SceneTopology t = good;
    t.graph.maxball.pop_back();
    EXPECT_THROW(topo::storeTopology(dir.path(), kKey, t), Error);
    t = good;
    t.voxelCluster.pop_back();
    EXPECT_THROW(topo::storeTopology(dir.path(), kKey, t), Error);
    t = good;
    t.segmentation.cluster[0] = t.segmentation.clusterCount;
    EXPECT_THROW(topo::storeTopology(dir.path(), kKey, t), Error);
    t = good;
    t.graph.adjacency[1].push_back(uint32_t(t.graph.position.size()));
    EXPECT_THROW(topo::storeTopology(dir.path(), kKey, t), Error);
    EXPECT_THROW(topo::storeTopology(dir.path(), "../escape", good), Error);
    EXPECT_THROW(topo::storeTopology(dir.path(), "0123456789ABCDEF0123456789ABCDEF", good), Error);
    std::string why;
    EXPECT_FALSE(topo::loadTopology(dir.path(), "../escape", &why).has_value());
    EXPECT_NE(why.find("invalid key"), std::string::npos) << why;
    EXPECT_TRUE(fs::is_empty(dir.path()));
}

TEST(CpuTopologyCache, StoreCreatesTheFolderAndSaysSo) {
    test::TempDir dir("topology_cache");
    const fs::path cache = dir.path() / "new" / "topology";
    testing::internal::CaptureStderr();
    topo::storeTopology(cache, kKey, syntheticTopology());
    const std::string err = testing::internal::GetCapturedStderr();
    EXPECT_TRUE(fs::is_regular_file(topo::topologyCacheFile(cache, kKey)));
    EXPECT_NE(err.find("creating the topology cache"), std::string::npos) << err;
    EXPECT_TRUE(topo::loadTopology(cache, kKey).has_value());
    // The second store into the existing folder is silent.
    testing::internal::CaptureStderr();
    topo::storeTopology(cache, kKey, syntheticTopology());
    EXPECT_EQ(testing::internal::GetCapturedStderr(), "");
}

TEST(CpuTopologyCache, DefaultDirFollowsGilabCache) {
    const char* old = std::getenv("GILAB_CACHE");
    const std::optional<std::string> saved = old ? std::optional<std::string>(old) : std::nullopt;
    ::setenv("GILAB_CACHE", "/somewhere/cache", 1);
    EXPECT_EQ(topo::defaultTopologyCacheDir(), fs::path("/somewhere/cache/topology"));
    ::setenv("GILAB_CACHE", "", 1);
    EXPECT_EQ(topo::defaultTopologyCacheDir(), fs::path("results/cache/topology"));
    ::unsetenv("GILAB_CACHE");
    EXPECT_EQ(topo::defaultTopologyCacheDir(), fs::path("results/cache/topology"));
    if (saved) ::setenv("GILAB_CACHE", saved->c_str(), 1);
}

// ---- the key ----

Material colour(glm::vec3 albedo) {
    Material m;
    m.baseColorFactor = glm::vec4(albedo, 1.0f);
    return m;
}

/** A floor, a wall and a masked panel (material 1, textured), with a light and a camera. */
Scene keyScene() {
    Scene s;
    s.name = "topology_key";
    s.sourcePath = "<test>";
    s.materials.push_back(colour(glm::vec3(0.5f)));
    Material masked = colour(glm::vec3(0.8f));
    masked.alphaMode = AlphaMode::Mask;
    masked.baseColorTexture = 0;
    s.materials.push_back(masked);
    Texture tex;
    tex.width = tex.height = 2;
    tex.rgba = {255, 0, 0, 255, 0, 255, 0, 0, 0, 0, 255, 255, 9, 9, 9, 0};
    s.textures.push_back(tex);
    appendQuad(s, {-1, 0, -1}, {1, 0, -1}, {1, 0, 1}, {-1, 0, 1}, {0, 1, 0}, 0);
    appendQuad(s, {-1, 0, -1}, {1, 0, -1}, {1, 2, -1}, {-1, 2, -1}, {0, 0, 1}, 0);
    appendQuad(s, {0, 0, -1}, {0, 0, 1}, {0, 1, 1}, {0, 1, -1}, {1, 0, 0}, 1);
    Light l;
    l.position = {0.0f, 1.5f, 0.0f};
    s.lights.push_back(l);
    s.camera.position = {0.0f, 1.0f, 3.0f};
    s.computeCaps();
    return s;
}

TEST(CpuTopologyKey, IsStableHexForTheSameScene) {
    const topo::TopologySettings settings;
    const std::string a = topo::topologyKey(keyScene(), settings);
    EXPECT_EQ(a.size(), 32u);
    EXPECT_EQ(a.find_first_not_of("0123456789abcdef"), std::string::npos) << a;
    EXPECT_EQ(topo::topologyKey(keyScene(), settings), a);
}

TEST(CpuTopologyKey, ChangesWithGeometryAndSettings) {
    const topo::TopologySettings settings;
    const std::string base = topo::topologyKey(keyScene(), settings);

    Scene s = keyScene();
    s.vertices[5].position.y += 1e-4f;  // one vertex of the wall
    EXPECT_NE(topo::topologyKey(s, settings), base);

    s = keyScene();
    std::swap(s.indices[0], s.indices[1]);
    EXPECT_NE(topo::topologyKey(s, settings), base);

    topo::TopologySettings other = settings;
    other.resolution = 128;
    EXPECT_NE(topo::topologyKey(keyScene(), other), base);
    other = settings;
    other.alpha = 0.25f;
    EXPECT_NE(topo::topologyKey(keyScene(), other), base);
    other = settings;
    EXPECT_TRUE(other.mergeVisible);  // the default: our visibility merge
    other.mergeVisible = false;
    const std::string literal = topo::topologyKey(keyScene(), other);
    EXPECT_NE(literal, base);
    EXPECT_EQ(topo::topologyKey(keyScene(), other), literal);
}

TEST(CpuTopologyKey, IgnoresMaterialsLightsCameraAndImage) {
    const topo::TopologySettings settings;
    const std::string base = topo::topologyKey(keyScene(), settings);
    Scene s = keyScene();
    s.name = "renamed";
    s.sourcePath = "/elsewhere/scene.json";
    s.materials[0].baseColorFactor = glm::vec4(0.1f, 0.9f, 0.2f, 1.0f);
    s.materials[0].roughness = 0.2f;
    s.materials[0].emissiveFactor = glm::vec3(3.0f);
    s.materials[0].alphaCutoff = 0.9f;  // opaque: the cutoff is not read
    s.materials[1].baseColorFactor.r = 0.0f;
    s.textures[0].rgba[0] = 17;  // colour, not alpha
    s.textures[0].colorSpace = ColorSpace::Linear;
    s.lights[0].intensity = glm::vec3(40.0f);
    s.lights[0].position.x = 0.7f;
    s.lights.push_back(Light{});
    s.camera.position = {4.0f, 4.0f, 4.0f};
    s.camera.vfovRad = 1.2f;
    s.settings.width = 64;
    s.settings.height = 48;
    s.settings.exposureEv = 2.0f;
    s.vertices[0].normal = glm::vec3(1.0f, 0.0f, 0.0f);
    s.vertices[0].uv = glm::vec2(0.3f, 0.7f);  // an opaque triangle's UV
    EXPECT_EQ(topo::topologyKey(s, settings), base);
}

TEST(CpuTopologyKey, AlphaMaskedMaterialsCount) {
    const topo::TopologySettings settings;
    const std::string base = topo::topologyKey(keyScene(), settings);
    Scene s = keyScene();
    s.materials[1].alphaCutoff = 0.3f;
    EXPECT_NE(topo::topologyKey(s, settings), base);
    s = keyScene();
    s.materials[1].baseColorFactor.a = 0.5f;
    EXPECT_NE(topo::topologyKey(s, settings), base);
    s = keyScene();
    s.textures[0].rgba[7] = 200;  // alpha of texel 1
    EXPECT_NE(topo::topologyKey(s, settings), base);
    s = keyScene();
    s.textures[0].wrapU = WrapMode::ClampToEdge;
    EXPECT_NE(topo::topologyKey(s, settings), base);
    s = keyScene();
    s.vertices.back().uv = glm::vec2(0.5f, 0.5f);  // a masked triangle's UV
    EXPECT_NE(topo::topologyKey(s, settings), base);
    s = keyScene();
    s.materials[1].alphaMode = AlphaMode::Opaque;
    EXPECT_NE(topo::topologyKey(s, settings), base);
    s = keyScene();  // Blend is voxelized as Mask
    s.materials[1].alphaMode = AlphaMode::Blend;
    EXPECT_EQ(topo::topologyKey(s, settings), base);
}

TEST(CpuTopologyKey, BadMaterialIndexNamesTheScene) {
    Scene s = keyScene();
    s.triangleMaterials[0] = 9;
    try {
        topo::topologyKey(s, topo::TopologySettings{});
        FAIL() << "no error";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("topology_key"), std::string::npos) << e.what();
    }
}

}  // namespace
}  // namespace gilab
