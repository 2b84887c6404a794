#include "topology_export.h"

#include <cmath>
#include <cstring>
#include <vector>

#include <tiny_gltf.h>

#include "core/util/error.h"
#include "scene_topology.h"

namespace gilab::topo {
namespace {

struct Primitive {
    std::vector<glm::vec3> positions, colours;
    std::vector<uint32_t> indices;  // empty: non-indexed
};

/** Appends bytes to the model's single buffer as a new view; returns the view index. */
int addView(tinygltf::Model& m, const void* data, size_t bytes, int target) {
    std::vector<unsigned char>& buf = m.buffers[0].data;
    while (buf.size() % 4)
        buf.push_back(0);
    tinygltf::BufferView v;
    v.buffer = 0;
    v.byteOffset = buf.size();
    v.byteLength = bytes;
    v.target = target;
    const auto* p = static_cast<const unsigned char*>(data);
    buf.insert(buf.end(), p, p + bytes);
    m.bufferViews.push_back(v);
    return int(m.bufferViews.size()) - 1;
}

int addVec3(tinygltf::Model& m, const std::vector<glm::vec3>& values, bool bounds) {
    tinygltf::Accessor a;
    a.bufferView =
        addView(m, values.data(), values.size() * sizeof(glm::vec3), TINYGLTF_TARGET_ARRAY_BUFFER);
    a.componentType = TINYGLTF_COMPONENT_TYPE_FLOAT;
    a.type = TINYGLTF_TYPE_VEC3;
    a.count = values.size();
    if (bounds && !values.empty()) {  // POSITION needs min and max
        glm::vec3 lo = values[0], hi = values[0];
        for (const glm::vec3& v : values) {
            lo = glm::min(lo, v);
            hi = glm::max(hi, v);
        }
        a.minValues = {lo.x, lo.y, lo.z};
        a.maxValues = {hi.x, hi.y, hi.z};
    }
    m.accessors.push_back(a);
    return int(m.accessors.size()) - 1;
}

void addMesh(tinygltf::Model& m, const std::string& name, const Primitive& p, int mode) {
    if (p.positions.empty()) return;
    tinygltf::Primitive prim;
    prim.mode = mode;
    prim.attributes["POSITION"] = addVec3(m, p.positions, true);
    prim.attributes["COLOR_0"] = addVec3(m, p.colours, false);
    if (!p.indices.empty()) {
        tinygltf::Accessor a;
        a.bufferView = addView(m, p.indices.data(), p.indices.size() * 4,
                               TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER);
        a.componentType = TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT;
        a.type = TINYGLTF_TYPE_SCALAR;
        a.count = p.indices.size();
        m.accessors.push_back(a);
        prim.indices = int(m.accessors.size()) - 1;
    }
    tinygltf::Mesh mesh;
    mesh.name = name;
    mesh.primitives.push_back(prim);
    m.meshes.push_back(mesh);
    tinygltf::Node node;
    node.name = name;
    node.mesh = int(m.meshes.size()) - 1;
    m.nodes.push_back(node);
    m.scenes[0].nodes.push_back(int(m.nodes.size()) - 1);
}

}  // namespace

glm::vec3 clusterColour(uint32_t c) {
    // Golden-ratio hue steps, full saturation: neighbouring ids get distant hues.
    const float h = std::fmod(0.618034f * float(c), 1.0f) * 6.0f;
    const float x = 1.0f - std::abs(std::fmod(h, 2.0f) - 1.0f);
    const int sector = int(h);
    const glm::vec3 rgb[6] = {{1, x, 0}, {x, 1, 0}, {0, 1, x}, {0, x, 1}, {x, 0, 1}, {1, 0, x}};
    return 0.2f + 0.8f * rgb[sector % 6];
}

void exportTopologyGltf(const SceneTopology& t, const std::string& path,
                        const std::vector<float>& gateRadii) {
    const Segmentation& s = t.segmentation;
    auto world = [&](uint32_t node) { return t.grid.gridToWorld(t.graph.position[node] + 0.5f); };
    Primitive lines, points, disks;
    for (uint32_t a : s.kept) {
        points.positions.push_back(world(a));
        points.colours.push_back(clusterColour(s.cluster[a]));
        for (uint32_t b : s.segmentedAdjacency[a]) {
            if (b <= a) continue;
            for (uint32_t e : {a, b}) {
                lines.indices.push_back(uint32_t(lines.positions.size()));
                lines.positions.push_back(world(e));
                lines.colours.push_back(clusterColour(s.cluster[e]));
            }
        }
    }
    constexpr int kSegments = 24;
    for (size_t i = 0; i < t.gates.size(); ++i) {
        const WorldGate& g = t.gates[i];
        const float radius = i < gateRadii.size() ? gateRadii[i] : g.radius;
        const glm::vec3 n = glm::normalize(g.normal);
        const glm::vec3 u = glm::normalize(
            glm::cross(n, std::abs(n.y) < 0.9f ? glm::vec3(0, 1, 0) : glm::vec3(1, 0, 0)));
        const glm::vec3 w = glm::cross(n, u);
        const uint32_t centre = uint32_t(disks.positions.size());
        disks.positions.push_back(g.centre);
        for (int k = 0; k < kSegments; ++k) {
            const float phi = 6.2831853f * float(k) / kSegments;
            disks.positions.push_back(g.centre + radius * (std::cos(phi) * u + std::sin(phi) * w));
        }
        disks.colours.insert(disks.colours.end(), kSegments + 1, clusterColour(g.clusterA));
        for (int k = 0; k < kSegments; ++k)
            disks.indices.insert(disks.indices.end(), {centre, centre + 1 + uint32_t(k),
                                                       centre + 1 + uint32_t((k + 1) % kSegments)});
    }
    tinygltf::Model m;
    m.asset.version = "2.0";
    m.asset.generator = "gilab topovpl topology export";
    m.buffers.resize(1);
    m.scenes.resize(1);
    m.defaultScene = 0;
    addMesh(m, "skeleton", lines, TINYGLTF_MODE_LINE);
    addMesh(m, "nodes", points, TINYGLTF_MODE_POINTS);
    addMesh(m, "gates", disks, TINYGLTF_MODE_TRIANGLES);
    tinygltf::TinyGLTF writer;
    if (!writer.WriteGltfSceneToFile(&m, path, /*embedImages=*/true, /*embedBuffers=*/true,
                                     /*prettyPrint=*/false, /*writeBinary=*/false))
        throw Error("topology export: cannot write " + path);
}

}  // namespace gilab::topo
