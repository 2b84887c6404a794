#include "topology_cache.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstddef>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iterator>
#include <map>
#include <new>
#include <string_view>
#include <system_error>

#include "core/scene/scene.h"
#include "core/util/atomic_file.h"
#include "core/util/error.h"
#include "core/util/hash.h"
#include "nearest_node.h"

namespace gilab::topo {
namespace {
namespace fs = std::filesystem;

// A field added to one of these must be serialized below (and kTopologyFormatVersion bumped); a
// new setting must be hashed in topologyKey. The sizes are those of x86-64 / AArch64.
static_assert(sizeof(TopologySettings) == 20, "hash the new setting in topologyKey");
static_assert(sizeof(SkeletonGraph) == 104, "serialize the new SkeletonGraph field");
static_assert(offsetof(SkeletonGraph, metric) == 100, "serialize the new SkeletonGraph field");
static_assert(sizeof(Gate) == 48, "serialize the new Gate field");
// Segmentation::pieces (24 bytes) is set-up only and deliberately not stored.
static_assert(sizeof(Segmentation) == 192, "serialize the new Segmentation field");
static_assert(sizeof(WorldGate) == 48, "serialize the new WorldGate field");
static_assert(sizeof(SceneTopology) == 400, "serialize the new SceneTopology field");

constexpr char kMagic[8] = {'G', 'I', 'L', 'A', 'B', 'T', 'O', 'P'};
constexpr size_t kChecksumBytes = 16;
constexpr size_t kGateBytes = 12 * 4;
constexpr bool kLittleEndianHost = std::endian::native == std::endian::little;

/** A little-endian byte stream (the cache file, and the key's input). */
class ByteWriter {
public:
    void u8(uint8_t v) { m_bytes.push_back(char(v)); }
    void u32(uint32_t v) {
        for (int i = 0; i < 4; ++i)
            m_bytes.push_back(char((v >> (8 * i)) & 0xffu));
    }
    void u64(uint64_t v) {
        for (int i = 0; i < 8; ++i)
            m_bytes.push_back(char((v >> (8 * i)) & 0xffu));
    }
    void f32(float v) { u32(std::bit_cast<uint32_t>(v)); }
    void vec2(const glm::vec2& v) {
        f32(v.x);
        f32(v.y);
    }
    void vec3(const glm::vec3& v) {
        f32(v.x);
        f32(v.y);
        f32(v.z);
    }
    void raw(std::string_view s) { m_bytes.append(s); }
    /** A length-prefixed string: tags in the key, the key in the file. */
    void text(std::string_view s) {
        u32(uint32_t(s.size()));
        raw(s);
    }
    void u32Array(const std::vector<uint32_t>& v) {
        u64(v.size());
        if constexpr (kLittleEndianHost) {
            m_bytes.append(reinterpret_cast<const char*>(v.data()), v.size() * 4);
        } else {
            for (uint32_t x : v)
                u32(x);
        }
    }
    void f32Array(const std::vector<float>& v) {
        u64(v.size());
        for (float x : v)
            f32(x);
    }
    void vec3Array(const std::vector<glm::vec3>& v) {
        u64(v.size());
        for (const glm::vec3& x : v)
            vec3(x);
    }
    void lists(const std::vector<std::vector<uint32_t>>& v) {
        u64(v.size());
        for (const std::vector<uint32_t>& list : v)
            u32Array(list);
    }
    template <class G>
    void gates(const std::vector<G>& v) {
        u64(v.size());
        for (const G& g : v) {
            vec3(g.centre);
            vec3(g.normal);
            f32(g.radiusNeck);
            f32(g.radius);
            f32(g.radiusA);
            f32(g.radiusB);
            u32(g.clusterA);
            u32(g.clusterB);
        }
    }
    std::string& bytes() { return m_bytes; }

private:
    std::string m_bytes;
};

/** Thrown inside loadTopology only; its message becomes `why`. */
struct Corrupt {
    std::string message;
};

[[noreturn]] void corrupt(const std::string& message) {
    throw Corrupt{message};
}

/** Reads the stream of ByteWriter; every length is checked against the bytes left. */
class ByteReader {
public:
    explicit ByteReader(std::string_view data) : m_data(data) {}

    size_t offset() const { return m_pos; }
    size_t remaining() const { return m_data.size() - m_pos; }
    std::string_view take(size_t n, const char* what) {
        if (n > remaining()) {
            corrupt(std::string("truncated in ") + what + " at byte " + std::to_string(m_pos) +
                    " (needs " + std::to_string(n) + " bytes, " + std::to_string(remaining()) +
                    " left)");
        }
        std::string_view s = m_data.substr(m_pos, n);
        m_pos += n;
        return s;
    }
    uint8_t u8(const char* what) { return uint8_t(take(1, what)[0]); }
    uint32_t u32(const char* what) {
        const std::string_view s = take(4, what);
        uint32_t v = 0;
        for (int i = 0; i < 4; ++i)
            v |= uint32_t(uint8_t(s[i])) << (8 * i);
        return v;
    }
    uint64_t u64(const char* what) {
        const std::string_view s = take(8, what);
        uint64_t v = 0;
        for (int i = 0; i < 8; ++i)
            v |= uint64_t(uint8_t(s[i])) << (8 * i);
        return v;
    }
    float f32(const char* what) { return std::bit_cast<float>(u32(what)); }
    glm::vec3 vec3(const char* what) {
        const float x = f32(what), y = f32(what), z = f32(what);
        return {x, y, z};
    }
    /** An element count, checked so that count x minBytes fits in what is left. */
    size_t count(const char* what, size_t minBytes) {
        const size_t at = m_pos;
        const uint64_t n = u64(what);
        if (n > remaining() / minBytes) {
            corrupt(std::string("length of ") + what + " at byte " + std::to_string(at) + " is " +
                    std::to_string(n) + ", more than the " + std::to_string(remaining()) +
                    " bytes left hold");
        }
        return size_t(n);
    }
    std::vector<uint32_t> u32Array(const char* what) {
        std::vector<uint32_t> v(count(what, 4));
        const std::string_view s = take(v.size() * 4, what);
        if constexpr (kLittleEndianHost) {
            if (!v.empty()) std::memcpy(v.data(), s.data(), s.size());
        } else {
            for (size_t i = 0; i < v.size(); ++i)
                for (int b = 0; b < 4; ++b)
                    v[i] |= uint32_t(uint8_t(s[4 * i + b])) << (8 * b);
        }
        return v;
    }
    std::vector<float> f32Array(const char* what) {
        std::vector<float> v(count(what, 4));
        for (float& x : v)
            x = f32(what);
        return v;
    }
    std::vector<glm::vec3> vec3Array(const char* what) {
        std::vector<glm::vec3> v(count(what, 12));
        for (glm::vec3& x : v)
            x = vec3(what);
        return v;
    }
    std::vector<std::vector<uint32_t>> lists(const char* what) {
        std::vector<std::vector<uint32_t>> v(count(what, 8));
        for (std::vector<uint32_t>& list : v)
            list = u32Array(what);
        return v;
    }
    template <class G>
    std::vector<G> gates(const char* what) {
        std::vector<G> v(count(what, kGateBytes));
        for (G& g : v) {
            g.centre = vec3(what);
            g.normal = vec3(what);
            g.radiusNeck = f32(what);
            g.radius = f32(what);
            g.radiusA = f32(what);
            g.radiusB = f32(what);
            g.clusterA = u32(what);
            g.clusterB = u32(what);
        }
        return v;
    }

private:
    std::string_view m_data;
    size_t m_pos = 0;
};

bool isHexKey(const std::string& key) {
    if (key.size() != 32) return false;
    for (char c : key)
        if (!((c >= '0' && c <= '9') || (c >= 'a' && c <= 'f'))) return false;
    return true;
}

/** The 16 bytes of a hashHex128 digest, in the order of its digits. */
std::string checksumBytes(std::string_view bytes) {
    const std::string hex = hashHex128(bytes);
    std::string out(kChecksumBytes, '\0');
    for (size_t i = 0; i < kChecksumBytes; ++i)
        out[i] = char(std::stoi(hex.substr(2 * i, 2), nullptr, 16));
    return out;
}

void checkIndices(const std::vector<uint32_t>& v, size_t bound, const std::string& what) {
    for (size_t i = 0; i < v.size(); ++i)
        if (v[i] >= bound) {
            corrupt(what + "[" + std::to_string(i) + "] = " + std::to_string(v[i]) +
                    " is out of range (" + std::to_string(bound) + ")");
        }
}

void checkSize(size_t size, size_t expected, const std::string& what, const char* of) {
    if (size != expected) {
        corrupt(what + " has " + std::to_string(size) + " entries, expected " +
                std::to_string(expected) + " (" + of + ")");
    }
}

template <class G>
void checkGates(const std::vector<G>& gates, uint32_t clusterCount, const char* what) {
    for (size_t i = 0; i < gates.size(); ++i) {
        const G& g = gates[i];
        if (g.clusterA >= clusterCount || g.clusterB >= clusterCount) {
            corrupt(std::string(what) + "[" + std::to_string(i) + "] joins clusters " +
                    std::to_string(g.clusterA) + " and " + std::to_string(g.clusterB) + " of " +
                    std::to_string(clusterCount));
        }
        // radius is min(radiusA, radiusB) exactly (a world radius too: scaling by the voxel size
        // is monotonic, so it commutes with min).
        if (!(g.radiusA >= 0.0f) || !(g.radiusB >= 0.0f) || !std::isfinite(g.radiusA) ||
            !std::isfinite(g.radiusB) || g.radius != std::min(g.radiusA, g.radiusB) ||
            !(g.radiusNeck >= 0.0f) || !(g.radiusNeck <= g.radius)) {
            corrupt(std::string(what) + "[" + std::to_string(i) + "] has radius " +
                    std::to_string(g.radius) + ", end radii " + std::to_string(g.radiusA) +
                    " and " + std::to_string(g.radiusB) + ", neck radius " +
                    std::to_string(g.radiusNeck) +
                    " (expected finite, >= 0, radius their minimum, the neck at most that)");
        }
    }
}

/** The invariants of buildSceneTopology that readers of a topology rely on (sizes that index
 *  each other, ids in range); throws Corrupt naming the first that fails. */
void checkConsistent(const SceneTopology& t) {
    const uint32_t res = t.grid.resolution();
    if (t.dims.nx != res || t.dims.ny != res || t.dims.nz != res) {
        corrupt("dims " + std::to_string(t.dims.nx) + "x" + std::to_string(t.dims.ny) + "x" +
                std::to_string(t.dims.nz) + " differ from the grid's resolution " +
                std::to_string(res));
    }
    const size_t voxels = t.dims.count();
    checkSize(t.voxelCluster.size(), voxels, "voxelCluster", "dims.count()");
    if (uint64_t(t.emptyVoxels) + t.solidVoxels != voxels || t.skeletonVoxels > t.emptyVoxels) {
        corrupt("voxel counts disagree: " + std::to_string(t.emptyVoxels) + " empty + " +
                std::to_string(t.solidVoxels) + " solid of " + std::to_string(voxels) + ", " +
                std::to_string(t.skeletonVoxels) + " skeleton");
    }

    const SkeletonGraph& g = t.graph;
    const size_t n = g.position.size();
    checkSize(g.maxball.size(), n, "graph.maxball", "graph.position");
    checkSize(g.adjacency.size(), n, "graph.adjacency", "graph.position");
    for (size_t i = 0; i < n; ++i)
        checkIndices(g.adjacency[i], n, "graph.adjacency[" + std::to_string(i) + "]");
    checkSize(g.voxelNode.size(), t.skeletonVoxels, "graph.voxelNode", "skeletonVoxels");
    checkIndices(g.voxelNode, n, "graph.voxelNode");

    const Segmentation& s = t.segmentation;
    checkSize(s.kind.size(), n, "segmentation.kind", "graph.position");
    checkSize(s.segmentedNode.size(), n, "segmentation.segmentedNode", "graph.position");
    checkSize(s.segmentedAdjacency.size(), n, "segmentation.segmentedAdjacency", "graph.position");
    checkSize(s.cluster.size(), n, "segmentation.cluster", "graph.position");
    for (size_t i = 0; i < n; ++i)
        if (uint8_t(s.kind[i]) > uint8_t(NodeKind::Coverage)) {
            corrupt("segmentation.kind[" + std::to_string(i) +
                    "] = " + std::to_string(int(s.kind[i])) + " is not a NodeKind");
        }
    checkIndices(s.segmentedNode, n, "segmentation.segmentedNode");
    checkIndices(s.kept, n, "segmentation.kept");
    for (size_t i = 0; i < n; ++i)
        checkIndices(s.segmentedAdjacency[i], n,
                     "segmentation.segmentedAdjacency[" + std::to_string(i) + "]");
    checkIndices(s.cluster, s.clusterCount, "segmentation.cluster");
    if (uint64_t(s.topologyNodes) + s.curvatureNodes + s.coverageNodes != s.kept.size()) {
        corrupt("segmentation counts " + std::to_string(s.topologyNodes) + " topology + " +
                std::to_string(s.curvatureNodes) + " curvature + " +
                std::to_string(s.coverageNodes) + " coverage nodes differ from " +
                std::to_string(s.kept.size()) + " kept");
    }
    if (s.greedyClusters < s.clusterCount) {
        corrupt("segmentation.greedyClusters " + std::to_string(s.greedyClusters) +
                " is below clusterCount " + std::to_string(s.clusterCount) +
                " (the merge only removes clusters)");
    }
    checkGates(s.gates, s.clusterCount, "segmentation.gates");
    for (size_t i = 0; i < t.voxelCluster.size(); ++i)
        if (t.voxelCluster[i] != kNoNode && t.voxelCluster[i] >= s.clusterCount) {
            corrupt("voxelCluster[" + std::to_string(i) +
                    "] = " + std::to_string(t.voxelCluster[i]) + " is out of range (" +
                    std::to_string(s.clusterCount) + " clusters)");
        }
    checkSize(t.gates.size(), s.gates.size(), "gates", "segmentation.gates");
    checkGates(t.gates, s.clusterCount, "gates");
}

std::string serialize(const std::string& key, const SceneTopology& t) {
    ByteWriter w;
    w.bytes().reserve(128 + t.voxelCluster.size() * 4 + t.graph.position.size() * 64);
    w.raw(std::string_view(kMagic, sizeof kMagic));
    w.u32(uint32_t(kTopologyFormatVersion));
    w.u32(uint32_t(kTopologyAlgorithmVersion));
    w.text(key);
    w.vec3(t.grid.origin());
    w.f32(t.grid.side());
    w.u32(t.grid.resolution());
    w.u32(t.dims.nx);
    w.u32(t.dims.ny);
    w.u32(t.dims.nz);
    w.u32(t.skeletonVoxels);
    w.u32(t.emptyVoxels);
    w.u32(t.solidVoxels);
    w.u64(t.anchoredVoxels);

    const SkeletonGraph& g = t.graph;
    w.vec3Array(g.position);
    w.f32Array(g.maxball);
    w.lists(g.adjacency);
    w.u32Array(g.voxelNode);
    w.u32(g.prunedNodes);
    w.u8(uint8_t(g.metric));

    const Segmentation& s = t.segmentation;
    w.u64(s.kind.size());
    for (NodeKind k : s.kind)
        w.u8(uint8_t(k));
    w.u32Array(s.segmentedNode);
    w.u32Array(s.kept);
    w.lists(s.segmentedAdjacency);
    w.u32Array(s.cluster);
    w.u32(s.clusterCount);
    w.u32(s.greedyClusters);
    w.gates(s.gates);
    w.u32(s.curvatureNodes);
    w.u32(s.coverageNodes);
    w.u32(s.topologyNodes);

    w.u32Array(t.voxelCluster);
    w.gates(t.gates);
    w.raw(checksumBytes(w.bytes()));
    return std::move(w.bytes());
}

SceneTopology deserialize(std::string_view data, const std::string& key) {
    ByteReader r(data);
    if (r.take(sizeof kMagic, "magic") != std::string_view(kMagic, sizeof kMagic))
        corrupt("not a topology file (bad magic)");
    const uint32_t format = r.u32("format version");
    if (format != uint32_t(kTopologyFormatVersion)) {
        corrupt("format version " + std::to_string(format) + ", expected " +
                std::to_string(kTopologyFormatVersion));
    }
    const uint32_t algorithm = r.u32("algorithm version");
    if (algorithm != uint32_t(kTopologyAlgorithmVersion)) {
        corrupt("algorithm version " + std::to_string(algorithm) + ", expected " +
                std::to_string(kTopologyAlgorithmVersion));
    }
    const uint32_t keyLength = r.u32("key");
    const std::string_view storedKey = r.take(keyLength, "key");
    if (storedKey != key) corrupt("holds key \"" + std::string(storedKey) + "\"");

    SceneTopology t;
    const glm::vec3 origin = r.vec3("grid");
    const float side = r.f32("grid");
    const uint32_t resolution = r.u32("grid");
    try {
        t.grid = VoxelGrid::fromCube(origin, side, resolution);
    } catch (const Error& e) {
        corrupt(e.what());
    }
    t.dims.nx = r.u32("dims");
    t.dims.ny = r.u32("dims");
    t.dims.nz = r.u32("dims");
    t.skeletonVoxels = r.u32("voxel counts");
    t.emptyVoxels = r.u32("voxel counts");
    t.solidVoxels = r.u32("voxel counts");
    t.anchoredVoxels = r.u64("anchored voxels");

    SkeletonGraph& g = t.graph;
    g.position = r.vec3Array("graph.position");
    g.maxball = r.f32Array("graph.maxball");
    g.adjacency = r.lists("graph.adjacency");
    g.voxelNode = r.u32Array("graph.voxelNode");
    g.prunedNodes = r.u32("graph.prunedNodes");
    const uint8_t metric = r.u8("graph.metric");
    if (metric > uint8_t(BallMetric::Chessboard))
        corrupt("graph.metric = " + std::to_string(metric) + " is not a ball metric");
    g.metric = BallMetric(metric);

    Segmentation& s = t.segmentation;
    s.kind.resize(r.count("segmentation.kind", 1));
    for (NodeKind& k : s.kind)
        k = NodeKind(r.u8("segmentation.kind"));
    s.segmentedNode = r.u32Array("segmentation.segmentedNode");
    s.kept = r.u32Array("segmentation.kept");
    s.segmentedAdjacency = r.lists("segmentation.segmentedAdjacency");
    s.cluster = r.u32Array("segmentation.cluster");
    s.clusterCount = r.u32("segmentation.clusterCount");
    s.greedyClusters = r.u32("segmentation.greedyClusters");
    s.gates = r.gates<Gate>("segmentation.gates");
    s.curvatureNodes = r.u32("segmentation counts");
    s.coverageNodes = r.u32("segmentation counts");
    s.topologyNodes = r.u32("segmentation counts");

    t.voxelCluster = r.u32Array("voxelCluster");
    t.gates = r.gates<WorldGate>("gates");

    const size_t end = r.offset();
    r.take(kChecksumBytes, "checksum");
    if (r.remaining() != 0) corrupt(std::to_string(r.remaining()) + " bytes after the checksum");
    if (data.substr(end, kChecksumBytes) != checksumBytes(data.substr(0, end)))
        corrupt("checksum mismatch");
    checkConsistent(t);
    return t;
}

}  // namespace

std::string topologyKey(const Scene& scene, const TopologySettings& settings) {
    const size_t triangles = scene.triangleCount();
    if (scene.indices.size() % 3 != 0 || scene.triangleMaterials.size() != triangles) {
        throw Error("topology key: scene '" + scene.name + "' has " +
                    std::to_string(scene.indices.size()) + " indices and " +
                    std::to_string(scene.triangleMaterials.size()) + " triangle materials");
    }
    ByteWriter w;
    w.bytes().reserve(256 + scene.vertices.size() * 12 + scene.indices.size() * 4);
    w.text("gilab.topology.key");
    w.u32(uint32_t(kTopologyFormatVersion));
    w.u32(uint32_t(kTopologyAlgorithmVersion));
    w.text("settings");
    w.u32(settings.resolution);
    w.f32(settings.alpha);
    w.u8(settings.mergeVisible ? 1 : 0);
    w.u8(uint8_t(settings.gatePlacement));
    w.f32(settings.mergeVisibility);
    w.u8(uint8_t(settings.clusterRule));
    w.u8(uint8_t(settings.ballMetric));
    w.u8(uint8_t(settings.coverageSplit));
    w.u8(uint8_t(settings.skeletonFilter));
    w.f32(VoxelGrid::kDefaultMargin);  // buildSceneTopology fits the grid with it
    w.u32(uint32_t(kBoundsMarginVoxels));
    w.text("bounds");
    w.vec3(scene.caps.bounds.lo);
    w.vec3(scene.caps.bounds.hi);
    w.text("positions");
    w.u64(scene.vertices.size());
    for (const Vertex& v : scene.vertices)
        w.vec3(v.position);
    w.text("indices");
    w.u32Array(scene.indices);

    // Alpha-masked triangles: the voxelizer drops fragments with base alpha < cutoff.
    std::map<uint32_t, uint32_t> maskId;  // material -> id, in order of first use
    std::vector<uint32_t> maskMaterials;
    ByteWriter masked;
    uint64_t maskedTriangles = 0;
    for (size_t t = 0; t < triangles; ++t) {
        const uint32_t m = scene.triangleMaterials[t];
        if (m >= scene.materials.size()) {
            throw Error("topology key: scene '" + scene.name + "': triangle " + std::to_string(t) +
                        " uses material " + std::to_string(m) + " of " +
                        std::to_string(scene.materials.size()));
        }
        if (scene.materials[m].alphaMode == AlphaMode::Opaque) continue;
        const auto [it, added] = maskId.emplace(m, uint32_t(maskMaterials.size()));
        if (added) maskMaterials.push_back(m);
        ++maskedTriangles;
        masked.u64(t);
        masked.u32(it->second);
        for (int k = 0; k < 3; ++k) {
            const uint32_t vi = scene.indices[3 * t + k];
            if (vi >= scene.vertices.size()) {
                throw Error("topology key: scene '" + scene.name + "': triangle " +
                            std::to_string(t) + " uses vertex " + std::to_string(vi) + " of " +
                            std::to_string(scene.vertices.size()));
            }
            masked.vec2(scene.vertices[vi].uv);
        }
    }
    w.text("alpha_mask");
    w.u64(maskedTriangles);
    w.raw(masked.bytes());
    w.u64(maskMaterials.size());
    for (uint32_t m : maskMaterials) {
        const Material& mat = scene.materials[m];
        w.f32(mat.baseColorFactor.a);
        w.f32(mat.alphaCutoff);
        if (mat.baseColorTexture < 0) {
            w.u8(0);
            continue;
        }
        if (size_t(mat.baseColorTexture) >= scene.textures.size()) {
            throw Error("topology key: scene '" + scene.name + "': material '" + mat.name +
                        "' uses texture " + std::to_string(mat.baseColorTexture) + " of " +
                        std::to_string(scene.textures.size()));
        }
        const Texture& tex = scene.textures[size_t(mat.baseColorTexture)];
        w.u8(1);
        w.u32(uint32_t(tex.width));
        w.u32(uint32_t(tex.height));
        w.u32(uint32_t(tex.wrapU));
        w.u32(uint32_t(tex.wrapV));
        w.u64(tex.rgba.size() / 4);
        for (size_t i = 3; i < tex.rgba.size(); i += 4)  // alpha only: sRGB decodes rgb
            w.u8(tex.rgba[i]);
    }
    return hashHex128(w.bytes());
}

fs::path defaultTopologyCacheDir() {
    if (const char* root = std::getenv("GILAB_CACHE"); root && *root)
        return fs::path(root) / "topology";
    return fs::path("results/cache/topology");
}

fs::path topologyCacheFile(const fs::path& dir, const std::string& key) {
    return dir / (key + ".topo");
}

void storeTopology(const fs::path& dir, const std::string& key, const SceneTopology& topology) {
    if (!isHexKey(key)) throw Error("topology cache: invalid key \"" + key + "\"");
    const fs::path file = topologyCacheFile(dir, key);
    try {
        checkConsistent(topology);
    } catch (const Corrupt& c) {
        throw Error("topology cache: refusing to store " + file.string() + ": " + c.message);
    }
    std::error_code ec;
    if (!fs::is_directory(dir, ec)) {
        std::fprintf(stderr,
                     "gilab: creating the topology cache %s (set GILAB_CACHE to use one cache "
                     "everywhere)\n",
                     fs::absolute(dir).lexically_normal().string().c_str());
        fs::create_directories(dir, ec);
        if (ec) {
            throw Error("topology cache: cannot create " + dir.string() + ": " + ec.message());
        }
    }
    writeFileAtomic(file, serialize(key, topology));
}

std::optional<SceneTopology> loadTopology(const fs::path& dir, const std::string& key,
                                          std::string* why) {
    if (why) why->clear();
    auto fail = [&](const std::string& reason) -> std::optional<SceneTopology> {
        if (why) *why = reason;
        return std::nullopt;
    };
    if (!isHexKey(key)) return fail("topology cache: invalid key \"" + key + "\"");
    fs::path file;
    try {
        file = topologyCacheFile(dir, key);
        std::error_code ec;
        if (!fs::exists(file, ec)) {
            if (ec) return fail("topology cache " + file.string() + ": " + ec.message());
            return std::nullopt;
        }
        std::ifstream in(file, std::ios::binary);
        std::string data;
        if (in) data.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
        if (!in && !in.eof()) return fail("topology cache " + file.string() + ": cannot read");
        return deserialize(data, key);
    } catch (const Corrupt& c) {
        return fail("topology cache " + file.string() + ": " + c.message);
    } catch (const std::bad_alloc&) {
        return fail("topology cache " + file.string() + ": out of memory");
    } catch (const std::exception& e) {
        return fail("topology cache " + file.string() + ": " + e.what());
    }
}

}  // namespace gilab::topo
