// Malformed glTF files (issue 15): every one must fail with a gilab::Error that names the file
// and the problem (and the accessor, bufferView, node, camera, light or material), never with a
// crash, std::bad_alloc, an out-of-range .at() or a huge allocation by a declared count.
#include <gtest/gtest.h>
#include <sys/stat.h>

#include "tests/temp_dir.h"

#include <atomic>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <new>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/scene/scene_loader.h"
#include "core/util/error.h"

// ---------------------------------------------------------------------------------------------
// The largest single allocation, to prove that declared counts are checked before allocating
// ---------------------------------------------------------------------------------------------

namespace {
std::atomic<size_t> g_largestAllocation{0};

void* trackedAlloc(size_t size) {
    size_t seen = g_largestAllocation.load(std::memory_order_relaxed);
    while (size > seen && !g_largestAllocation.compare_exchange_weak(seen, size)) {
    }
    if (void* p = std::malloc(size ? size : 1)) return p;
    throw std::bad_alloc();
}
}  // namespace

void* operator new(size_t size) {
    return trackedAlloc(size);
}
void* operator new[](size_t size) {
    return trackedAlloc(size);
}
void operator delete(void* p) noexcept {
    std::free(p);
}
void operator delete[](void* p) noexcept {
    std::free(p);
}
void operator delete(void* p, size_t) noexcept {
    std::free(p);
}
void operator delete[](void* p, size_t) noexcept {
    std::free(p);
}

using namespace gilab;
using nlohmann::json;
namespace fs = std::filesystem;

namespace {

constexpr int kByte = 5120, kUByte = 5121, kShort = 5122, kUShort = 5123, kUInt = 5125,
              kFloat = 5126;

class TempDir : public test::TempDir {
public:
    TempDir() : test::TempDir("gilab_gltf_hardening") {}
};

/** Runs `fn`, expects a gilab::Error holding every fragment; returns its message. */
template <typename Fn>
std::string expectError(Fn&& fn, std::initializer_list<std::string> fragments) {
    try {
        fn();
        ADD_FAILURE() << "expected gilab::Error";
    } catch (const Error& e) {
        const std::string msg = e.what();
        for (const std::string& f : fragments) {
            EXPECT_NE(msg.find(f), std::string::npos) << "'" << f << "' not in: " << msg;
        }
        EXPECT_EQ(msg.find("internal error"), std::string::npos) << msg;
        return msg;
    }
    return "";
}

std::string base64(const std::string& bytes) {
    static const char* table = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    std::string out;
    for (size_t i = 0; i < bytes.size(); i += 3) {
        uint32_t v = uint32_t(uint8_t(bytes[i])) << 16;
        if (i + 1 < bytes.size()) v |= uint32_t(uint8_t(bytes[i + 1])) << 8;
        if (i + 2 < bytes.size()) v |= uint32_t(uint8_t(bytes[i + 2]));
        out += table[(v >> 18) & 63];
        out += table[(v >> 12) & 63];
        out += i + 1 < bytes.size() ? table[(v >> 6) & 63] : '=';
        out += i + 2 < bytes.size() ? table[v & 63] : '=';
    }
    return out;
}

/**
 * A valid one-triangle glTF (mesh 0 on node 0 in scene 0, accessor 0 = POSITION) that each
 * test breaks in one way. One embedded buffer; one bufferView per accessor.
 */
class Gltf {
public:
    Gltf() {
        doc = {{"asset", {{"version", "2.0"}}},
               {"scenes", {{{"nodes", {0}}}}},
               {"scene", 0},
               {"nodes", {{{"mesh", 0}}}},
               {"meshes", json::array()},
               {"accessors", json::array()},
               {"bufferViews", json::array()}};
        const int pos = accessor(std::vector<float>{0, 0, 0, 1, 0, 0, 0, 1, 0}, kFloat, "VEC3", 3);
        doc["meshes"].push_back(
            {{"name", "tri"}, {"primitives", {{{"attributes", {{"POSITION", pos}}}}}}});
    }
    /** Appends `data` as a new bufferView and an accessor over it; returns the accessor. */
    template <typename T>
    int accessor(const std::vector<T>& data, int componentType, const char* type, size_t count) {
        const size_t offset = m_bin.size();
        m_bin.append(reinterpret_cast<const char*>(data.data()), data.size() * sizeof(T));
        while (m_bin.size() % 4)
            m_bin.push_back('\0');
        doc["bufferViews"].push_back(
            {{"buffer", 0}, {"byteOffset", offset}, {"byteLength", data.size() * sizeof(T)}});
        doc["accessors"].push_back({{"bufferView", doc["bufferViews"].size() - 1},
                                    {"componentType", componentType},
                                    {"type", type},
                                    {"count", count}});
        return int(doc["accessors"].size() - 1);
    }
    json& primitive() { return doc["meshes"][0]["primitives"][0]; }
    json& node(size_t i = 0) { return doc["nodes"][i]; }
    /** Adds a perspective camera and a node for it (child of nothing, listed in scene 0). */
    json& camera(const json& perspective = {{"yfov", 0.7}, {"znear", 0.1}}) {
        doc["cameras"] = {{{"type", "perspective"}, {"perspective", perspective}}};
        doc["nodes"].push_back({{"camera", 0}});
        doc["scenes"][0]["nodes"].push_back(doc["nodes"].size() - 1);
        return doc["nodes"].back();
    }
    /** Adds KHR_lights_punctual light 0 and a node for it (listed in scene 0). */
    json& light(const json& light) {
        doc["extensionsUsed"] = {"KHR_lights_punctual"};
        doc["extensions"] = {{"KHR_lights_punctual", {{"lights", {light}}}}};
        doc["nodes"].push_back({{"extensions", {{"KHR_lights_punctual", {{"light", 0}}}}}});
        doc["scenes"][0]["nodes"].push_back(doc["nodes"].size() - 1);
        return doc["nodes"].back();
    }
    /** Gives the primitive material 0 = `material` (pbrMetallicRoughness etc. as given). */
    void material(const json& material) {
        doc["materials"] = {material};
        primitive()["material"] = 0;
    }
    std::string write(const TempDir& dir, const std::string& name) {
        doc["buffers"] = {{{"byteLength", m_bin.size()},
                           {"uri", "data:application/octet-stream;base64," + base64(m_bin)}}};
        std::string text = doc.dump(2);
        // JSON has no NaN or Inf: kOverflow becomes 1e999, which overflows a double
        for (size_t at; (at = text.find(kOverflowText)) != std::string::npos;)
            text.replace(at, kOverflowText.size(), "1e999");
        return dir.write(name, text);
    }
    /** The same file as .glb: `binLength` overrides the BIN chunk's declared length. */
    std::string writeGlb(const TempDir& dir, const std::string& name, int64_t binLength = -1) {
        doc["buffers"] = {{{"byteLength", m_bin.size()}}};
        std::string text = doc.dump();
        while (text.size() % 4)
            text.push_back(' ');
        auto u32 = [](uint32_t v) { return std::string(reinterpret_cast<const char*>(&v), 4); };
        const uint32_t total = uint32_t(12 + 8 + text.size() + 8 + m_bin.size());
        const uint32_t bin = binLength >= 0 ? uint32_t(binLength) : uint32_t(m_bin.size());
        return dir.write(name, "glTF" + u32(2) + u32(total) + u32(uint32_t(text.size())) + "JSON" +
                                   text + u32(bin) + std::string("BIN\0", 4) + m_bin);
    }
    json doc;
    /** Written as 1e999 (a number no double holds). */
    static constexpr double kOverflow = 123456.75;
    inline static const std::string kOverflowText = "123456.75";

private:
    std::string m_bin;
};

/** Writes `g` as `name` and expects loadGltf to fail naming the file and every fragment. */
std::string expectLoadError(Gltf& g, const std::string& name,
                            std::initializer_list<std::string> fragments) {
    TempDir dir;
    const std::string path = g.write(dir, name);
    SCOPED_TRACE(name);
    const std::string msg = expectError([&] { loadGltf(path); }, fragments);
    EXPECT_NE(msg.find(path), std::string::npos) << "path not in: " << msg;
    return msg;
}

// ---------------------------------------------------------------------------------------------
// 1. Declared counts, offsets and sizes are checked before anything of that size is allocated
// ---------------------------------------------------------------------------------------------

TEST(CpuGltfHardening, ValidBaseFileLoads) {
    Gltf g;
    TempDir dir;
    const Scene s = loadGltf(g.write(dir, "ok.gltf"));
    EXPECT_EQ(s.triangleCount(), 1u);
    // The generic entry point takes the same path
    EXPECT_EQ(loadScene(g.write(dir, "ok2.gltf")).triangleCount(), 1u);
}

TEST(CpuGltfHardening, HugeCountIsRejectedBeforeAllocation) {
    for (const size_t count : {size_t(1) << 27, size_t(1) << 31, size_t(1) << 40}) {
        Gltf g;
        g.doc["accessors"][0]["count"] = count;  // the view holds 36 bytes
        g_largestAllocation = 0;
        const std::string name = "count" + std::to_string(count) + ".gltf";
        expectLoadError(
            g, name,
            {"mesh 'tri' primitive 0 POSITION (accessor 0)",
             "count " + std::to_string(count) + " does not fit bufferView 0", "the view has 36"});
        EXPECT_LT(g_largestAllocation.load(), size_t(64) << 20) << name;
    }
    // 2^27 VEC3 floats in a 96-byte view: 1.5 GB declared
    Gltf g;
    const int big = g.accessor(std::vector<float>(24, 0.0f), kFloat, "VEC3", size_t(1) << 27);
    g.primitive()["attributes"]["NORMAL"] = big;
    g_largestAllocation = 0;
    expectLoadError(g, "normal96.gltf",
                    {"NORMAL (accessor 1)", "count 134217728 does not fit bufferView 1",
                     "need 1610612736 bytes", "the view has 96"});
    EXPECT_LT(g_largestAllocation.load(), size_t(64) << 20);
}

TEST(CpuGltfHardening, OffsetOverflowIsCaught) {
    Gltf g;
    // byteOffset + size wraps around 2^64 unless checked
    g.doc["accessors"][0]["byteOffset"] = std::numeric_limits<uint64_t>::max() - 7;
    expectLoadError(g, "offset.gltf", {"accessor 0", "does not fit bufferView 0"});

    Gltf h;
    h.doc["accessors"][0]["count"] = (uint64_t(1) << 62) + 1;  // (count - 1) * 12 overflows
    g_largestAllocation = 0;
    expectLoadError(h, "wrap.gltf", {"accessor 0", "does not fit", "more than 2^64"});
    EXPECT_LT(g_largestAllocation.load(), size_t(64) << 20);
}

TEST(CpuGltfHardening, BufferViewPastItsBuffer) {
    Gltf g;
    g.doc["bufferViews"][0]["byteLength"] = 4000;
    // tinygltf may catch this itself; either way the file is named and nothing crashes
    TempDir dir;
    const std::string path = g.write(dir, "view.gltf");
    const std::string msg = expectError([&] { loadGltf(path); }, {path});
    EXPECT_TRUE(msg.find("bufferView") != std::string::npos ||
                msg.find("malformed glTF") != std::string::npos)
        << msg;

    Gltf h;
    h.doc["bufferViews"][0]["byteOffset"] = std::numeric_limits<uint64_t>::max() - 3;
    h.doc["bufferViews"][0]["byteLength"] = 36;
    const std::string path2 = h.write(dir, "viewoffset.gltf");
    expectError([&] { loadGltf(path2); }, {path2});
}

TEST(CpuGltfHardening, MalformedContainers) {
    TempDir dir;
    Gltf g;
    EXPECT_EQ(loadGltf(g.writeGlb(dir, "ok.glb")).triangleCount(), 1u);
    // The BIN chunk claims more bytes than the file has
    const std::string bin = g.writeGlb(dir, "binlength.glb", 1 << 30);
    expectError([&] { loadGltf(bin); }, {bin});
    // Truncated after the header and inside the JSON chunk
    const std::string full = g.writeGlb(dir, "full.glb");
    std::ifstream in(full, std::ios::binary);
    const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    for (size_t cut : {size_t(4), size_t(12), size_t(20), size_t(40), bytes.size() - 8}) {
        const std::string path =
            dir.write("cut" + std::to_string(cut) + ".glb", bytes.substr(0, cut));
        expectError([&] { loadGltf(path); }, {path});
    }
    // An embedded buffer shorter than its declared byteLength
    Gltf h;
    h.write(dir, "unused.gltf");
    h.doc["buffers"][0]["byteLength"] = 4096;
    const std::string shortBuffer = dir.write("shortbuffer.gltf", h.doc.dump());
    expectError([&] { loadGltf(shortBuffer); }, {shortBuffer});
}

TEST(CpuGltfHardening, AccessorWithoutBufferViewIsLimited) {
    Gltf g;
    g.doc["accessors"][0].erase("bufferView");
    g.doc["accessors"][0]["count"] = uint64_t(1) << 31;
    g_largestAllocation = 0;
    expectLoadError(g, "zeros.gltf",
                    {"accessor 0", "count 2147483648 with no bufferView", "exceeds the limit"});
    EXPECT_LT(g_largestAllocation.load(), size_t(64) << 20);
}

TEST(CpuGltfHardening, SparseCountsAndIndices) {
    Gltf g;
    const int idx = g.accessor(std::vector<uint16_t>{7}, kUShort, "SCALAR", 1);
    const int val = g.accessor(std::vector<float>{2, 2, 0}, kFloat, "VEC3", 1);
    const json sparse = {
        {"count", 1},
        {"indices",
         {{"bufferView", g.doc["accessors"][idx]["bufferView"]}, {"componentType", kUShort}}},
        {"values", {{"bufferView", g.doc["accessors"][val]["bufferView"]}}}};
    g.doc["accessors"][0]["sparse"] = sparse;
    expectLoadError(g, "sparseindex.gltf", {"accessor 0", "sparse index 7 out of range"});

    Gltf h = g;
    h.doc["accessors"][0]["sparse"]["count"] = 1000000;  // more than the accessor's 3
    expectLoadError(h, "sparsecount.gltf", {"accessor 0", "sparse count 1000000"});
}

// ---------------------------------------------------------------------------------------------
// 2. Out-of-range indices
// ---------------------------------------------------------------------------------------------

TEST(CpuGltfHardening, OutOfRangeAccessorAndBufferIndices) {
    {
        Gltf g;
        g.doc["accessors"][0]["bufferView"] = 9;
        expectLoadError(g, "acc_view.gltf", {"accessor 0", "bufferView 9 does not exist"});
    }
    {
        Gltf g;
        g.doc["bufferViews"][0]["buffer"] = 5;
        // tinygltf or the loader: the file is named either way
        TempDir dir;
        const std::string path = g.write(dir, "view_buffer.gltf");
        expectError([&] { loadGltf(path); }, {path});
    }
    {
        Gltf g;
        g.primitive()["attributes"]["POSITION"] = 42;
        expectLoadError(g, "pos.gltf", {"POSITION", "accessor 42 does not exist"});
    }
    {
        Gltf g;
        g.primitive()["attributes"]["NORMAL"] = -3;
        expectLoadError(g, "normal.gltf", {"NORMAL", "accessor -3 does not exist"});
    }
    {
        Gltf g;
        g.primitive()["indices"] = 42;
        expectLoadError(g, "indices.gltf", {"indices accessor out of bounds"});
    }
}

TEST(CpuGltfHardening, OutOfRangeNodeSceneAndMaterialIndices) {
    {
        Gltf g;
        g.node()["mesh"] = 3;
        expectLoadError(g, "mesh.gltf", {"node 0", "references mesh 3, which does not exist"});
    }
    {
        Gltf g;
        g.node()["camera"] = 2;
        expectLoadError(g, "camera.gltf", {"node 0", "references camera 2, which does not exist"});
    }
    {
        Gltf g;
        g.node()["children"] = {9};
        expectLoadError(g, "child.gltf", {"node 0", "lists child node 9, which does not exist"});
    }
    {
        Gltf g;
        g.doc["scenes"][0]["nodes"] = {0, 9};
        expectLoadError(g, "scenenode.gltf", {"scene 0 lists node 9, which does not exist"});
    }
    {
        Gltf g;
        g.doc["scene"] = 3;
        expectLoadError(g, "defaultscene.gltf", {"default scene 3 does not exist"});
    }
    {
        Gltf g;
        g.primitive()["material"] = 4;
        expectLoadError(g, "material.gltf", {"primitive 0", "material 4 does not exist"});
    }
    {
        Gltf g;  // two parents: with repeats the walk would grow exponentially
        g.doc["nodes"] = {{{"children", {1, 1}}}, {{"mesh", 0}}};
        expectLoadError(g, "twice.gltf", {"node 0 lists child node 1 twice"});
        g.doc["nodes"] = {{{"children", {1}}}, {{"mesh", 0}}, {{"children", {1}}}};
        g.doc["scenes"][0]["nodes"] = {0, 2};
        expectLoadError(g, "parents.gltf", {"node 1", "has two parents (nodes 0 and 2)"});
    }
    {
        Gltf g;
        g.doc["nodes"] = {{{"children", {1}}}, {{"mesh", 0}}};
        g.doc["scenes"][0]["nodes"] = {0, 1};
        expectLoadError(g, "root.gltf", {"scene 0 lists node 1 as a root", "child of node 0"});
    }
    {
        Gltf g;
        g.light({{"type", "point"}});
        g.doc["nodes"].back()["extensions"]["KHR_lights_punctual"]["light"] = 3;
        expectLoadError(g, "lightindex.gltf", {"references light 3, which does not exist"});
    }
}

TEST(CpuGltfHardening, DeepHierarchyIsRefusedBeforeTheStackOverflows) {
    Gltf g;
    const int depth = 5000;
    g.doc["nodes"] = json::array();
    for (int i = 0; i < depth; ++i)
        g.doc["nodes"].push_back({{"children", {i + 1}}});
    g.doc["nodes"].push_back({{"mesh", 0}});
    expectLoadError(g, "deep.gltf", {"node hierarchy is deeper than 1024 levels"});
}

TEST(CpuGltfHardening, OutOfRangeTextureImageAndSamplerIndices) {
    auto textured = [] {
        Gltf g;
        g.material(
            {{"name", "m"}, {"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 0}}}}}});
        g.doc["textures"] = {{{"source", 0}}};
        g.doc["images"] = {{{"uri", "absent.png"}}};
        return g;
    };
    {
        Gltf g = textured();
        g.doc["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"]["index"] = 3;
        expectLoadError(g, "texture.gltf", {"material 'm'", "missing texture 3"});
    }
    {
        Gltf g = textured();
        g.doc["textures"][0]["source"] = 5;
        expectLoadError(g, "image.gltf", {"texture 0", "image 5, which does not exist"});
    }
    {
        Gltf g = textured();
        g.doc["textures"][0]["sampler"] = 2;
        expectLoadError(g, "sampler.gltf", {"texture 0", "sampler 2, which does not exist"});
    }
}

TEST(CpuGltfHardening, VertexIndexBeyondVertexCount) {
    Gltf g;
    g.primitive()["indices"] = g.accessor(std::vector<uint32_t>{0, 1, 3}, kUInt, "SCALAR", 3);
    expectLoadError(g, "vertexindex.gltf", {"mesh 'tri' primitive 0", "1 indices out of range"});
}

// ---------------------------------------------------------------------------------------------
// 3. Component types, element types and strides the spec does not allow
// ---------------------------------------------------------------------------------------------

TEST(CpuGltfHardening, AttributeTypesAndStrides) {
    {
        Gltf g;
        g.primitive()["attributes"]["POSITION"] =
            g.accessor(std::vector<uint8_t>{0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0}, kUByte, "VEC3", 3);
        expectLoadError(g, "posbyte.gltf",
                        {"POSITION (accessor 1)", "componentType UNSIGNED_BYTE is not allowed",
                         "POSITION must be FLOAT VEC3"});
    }
    {
        Gltf g;
        g.doc["accessors"][0]["type"] = "VEC2";
        expectLoadError(g, "posvec2.gltf", {"POSITION (accessor 0)", "type VEC2 where VEC3"});
    }
    {
        Gltf g;
        const int n =
            g.accessor(std::vector<int16_t>{0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 0}, kShort, "VEC3", 3);
        g.doc["accessors"][n]["normalized"] = true;
        g.doc["bufferViews"][g.doc["accessors"][n]["bufferView"].get<int>()]["byteStride"] = 8;
        g.primitive()["attributes"]["NORMAL"] = n;
        expectLoadError(g, "normalshort.gltf",
                        {"NORMAL (accessor 1)", "componentType SHORT is not allowed"});
    }
    {
        Gltf g;  // TEXCOORD_0 as unnormalized bytes
        g.primitive()["attributes"]["TEXCOORD_0"] =
            g.accessor(std::vector<uint8_t>{0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0}, kUByte, "VEC2", 3);
        g.doc["bufferViews"][1]["byteStride"] = 4;
        expectLoadError(g, "uvbyte.gltf",
                        {"TEXCOORD_0 (accessor 1)", "UNSIGNED_BYTE is not allowed",
                         "normalized UNSIGNED_BYTE"});
    }
    {
        Gltf g;
        g.primitive()["indices"] = g.accessor(std::vector<float>{0, 1, 2}, kFloat, "SCALAR", 3);
        expectLoadError(g, "indexfloat.gltf",
                        {"indices (accessor 1)", "componentType FLOAT is not allowed"});
    }
    {
        Gltf g;
        g.primitive()["indices"] = g.accessor(std::vector<int8_t>{0, 1, 2, 0}, kByte, "SCALAR", 3);
        expectLoadError(g, "indexbyte.gltf", {"indices (accessor 1)", "BYTE is not allowed"});
    }
    {
        Gltf g;  // stride 4 < 12 bytes of a float VEC3
        g.doc["bufferViews"][0]["byteStride"] = 4;
        expectLoadError(g, "stride.gltf",
                        {"POSITION (accessor 0)",
                         "bufferView 0 byteStride 4 is smaller than the "
                         "element size (12 bytes"});
    }
    {
        Gltf g;  // not a multiple of 4: refused while parsing
        g.doc["bufferViews"][0]["byteStride"] = 14;
        expectLoadError(g, "stride14.gltf", {"malformed glTF", "byteStride"});
    }
}

// ---------------------------------------------------------------------------------------------
// 4. Cameras, lights and node transforms
// ---------------------------------------------------------------------------------------------

TEST(CpuGltfHardening, CameraProjection) {
    auto check = [](const json& perspective, const std::string& name,
                    std::initializer_list<std::string> fragments) {
        Gltf g;
        g.camera(perspective);
        expectLoadError(g, name, fragments);
    };
    check({{"yfov", 0.7}, {"znear", 0.0}}, "znear0.gltf", {"camera 0", "invalid znear 0"});
    check({{"yfov", 0.7}, {"znear", -1.0}}, "znearneg.gltf", {"camera 0", "invalid znear -1"});
    check({{"yfov", 0.7}, {"znear", 1.0}, {"zfar", 0.5}}, "zfar.gltf",
          {"camera 0", "invalid zfar 0.5", "greater than znear 1"});
    check({{"yfov", 0.0}, {"znear", 0.1}}, "yfov0.gltf", {"camera 0", "invalid yfov 0"});
    check({{"yfov", 3.2}, {"znear", 0.1}}, "yfovpi.gltf", {"camera 0", "invalid yfov 3.2"});
    check({{"yfov", 0.7}, {"znear", 0.1}, {"aspectRatio", -1.0}}, "aspect.gltf",
          {"camera 0", "invalid aspectRatio -1"});
}

TEST(CpuGltfHardening, DegenerateCameraTransforms) {
    {
        Gltf g;
        g.camera()["scale"] = {0, 0, 0};
        expectLoadError(g, "camscale.gltf",
                        {"node 1", "camera 0", "degenerate world transform", "no view direction"});
    }
    {
        Gltf g;  // zero linear part, affine last row
        g.camera()["matrix"] = {0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 1, 2, 3, 1};
        expectLoadError(g, "camzero.gltf", {"node 1", "camera 0", "degenerate world transform"});
    }
    {
        Gltf g;  // all-zero matrix
        g.camera()["matrix"] = json::array();
        for (int i = 0; i < 16; ++i)
            g.doc["nodes"][1]["matrix"].push_back(0);
        expectLoadError(g, "camallzero.gltf", {"node 1", "matrix is not an affine TRS matrix"});
    }
    {
        Gltf g;  // -Z and +Y collapse onto one line
        g.camera()["matrix"] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 0, 0, 1};
        expectLoadError(g, "camflat.gltf", {"node 1", "degenerate world transform"});
    }
    {
        Gltf g;  // a parent's scale 0 degenerates the child camera too
        json& cam = g.camera();
        cam["scale"] = {1, 1, 1};
        g.doc["nodes"].push_back({{"scale", {0, 0, 0}}, {"children", {1}}});
        g.doc["scenes"][0]["nodes"] = {0, 2};
        expectLoadError(g, "camparent.gltf", {"node 1", "degenerate world transform"});
    }
    {
        Gltf g;
        g.camera()["translation"] = {1e39, 0, 0};  // overflows a float
        expectLoadError(g, "camfar.gltf", {"node 1", "translation", "infinite"});
    }
    {
        Gltf g;  // finite, but position + forward rounds back to the position
        g.camera()["translation"] = {0, 0, 1e30};  // looks down -z
        expectLoadError(g, "camfar2.gltf", {"node 1", "camera 0", "too far from the origin"});
    }
}

TEST(CpuGltfHardening, ZeroLengthQuaternionOnAnyNode) {
    {
        Gltf g;
        g.node()["rotation"] = {0, 0, 0, 0};
        expectLoadError(g, "quatmesh.gltf", {"node 0", "rotation quaternion", "zero length"});
    }
    {
        Gltf g;
        g.camera()["rotation"] = {0, 0, 0, 0};
        expectLoadError(g, "quatcam.gltf", {"node 1", "rotation quaternion", "zero length"});
    }
    {
        Gltf g;  // a non-unit quaternion is normalized, not rejected
        g.node()["rotation"] = {0, 0, 0, 2};
        TempDir dir;
        EXPECT_EQ(loadGltf(g.write(dir, "quat2.gltf")).triangleCount(), 1u);
    }
}

TEST(CpuGltfHardening, LightsAreChecked) {
    auto check = [](const json& light, const std::string& name,
                    std::initializer_list<std::string> fragments) {
        Gltf g;
        g.light(light);
        expectLoadError(g, name, fragments);
    };
    check({{"type", "point"}, {"intensity", -1}}, "lightneg.gltf",
          {"light 0", "invalid intensity -1"});
    check({{"type", "point"}, {"intensity", Gltf::kOverflow}}, "lightinf.gltf",
          {"malformed glTF", "number overflow", "1e999"});
    check({{"type", "point"}, {"color", {1, -0.5, 1}}}, "lightcolor.gltf",
          {"light 0", "invalid color component -0.5"});
    check({{"type", "point"}, {"range", -2}}, "lightrange.gltf", {"light 0", "invalid range -2"});
    check({{"type", "spot"}, {"spot", {{"innerConeAngle", 0.6}, {"outerConeAngle", 0.5}}}},
          "spotorder.gltf", {"light 0", "invalid cone angles inner 0.6, outer 0.5"});
    check({{"type", "spot"}, {"spot", {{"outerConeAngle", 2.0}}}}, "spotwide.gltf",
          {"light 0", "invalid cone angles", "pi/2"});

    Gltf g;
    g.light({{"type", "spot"}, {"spot", json::object()}})["scale"] = {0, 0, 0};
    expectLoadError(g, "lightscale.gltf",
                    {"node 1", "light 0", "degenerate world transform", "no direction"});

    Gltf ok;  // a valid light under a rotated, scaled node keeps a unit direction
    ok.light({{"type", "spot"}, {"spot", json::object()}, {"intensity", 3}})["scale"] = {2, 2, 2};
    TempDir dir;
    const Scene s = loadGltf(ok.write(dir, "lightok.gltf"));
    ASSERT_EQ(s.lights.size(), 1u);
    EXPECT_NEAR(glm::length(s.lights[0].direction), 1.0f, 1e-6f);
}

TEST(CpuGltfHardening, NonFiniteNodeTransforms) {
    {
        Gltf g;
        g.node()["scale"] = {1e39, 1, 1};
        expectLoadError(g, "scaleinf.gltf", {"node 0", "scale", "infinite"});
    }
    {
        Gltf g;  // finite matrix, but world positions overflow a float
        g.node()["scale"] = {3e38, 3e38, 3e38};
        g.primitive()["attributes"]["POSITION"] =
            g.accessor(std::vector<float>{0, 0, 0, 10, 0, 0, 0, 10, 0}, kFloat, "VEC3", 3);
        expectLoadError(g, "overflow.gltf", {"mesh 'tri' primitive 0", "overflow a float"});
    }
    {
        Gltf g;
        g.node()["matrix"] = {1, 0, 0};
        expectLoadError(g, "matrix3.gltf", {"node 0", "matrix has 3 numbers"});
    }
}

// ---------------------------------------------------------------------------------------------
// 5. Materials: one policy (docs/conventions.md): invalid factors are an error
// ---------------------------------------------------------------------------------------------

TEST(CpuGltfHardening, PhysicallyInvalidMaterials) {
    auto check = [](const json& material, const std::string& name,
                    std::initializer_list<std::string> fragments) {
        Gltf g;
        g.material(material);
        expectLoadError(g, name, fragments);
    };
    check({{"name", "red"}, {"pbrMetallicRoughness", {{"baseColorFactor", {1, -0.2, 0, 1}}}}},
          "basecolor.gltf", {"material 0 'red'", "invalid baseColorFactor[1] -0.2", "[0, 1]"});
    check({{"pbrMetallicRoughness", {{"baseColorFactor", {1.5, 1, 1, 1}}}}}, "basecolor1.gltf",
          {"material 0", "invalid baseColorFactor[0] 1.5"});
    check({{"pbrMetallicRoughness", {{"baseColorFactor", {Gltf::kOverflow, 1, 1, 1}}}}},
          "basecolorinf.gltf", {"malformed glTF", "number overflow", "1e999"});
    check({{"emissiveFactor", {1, 1, -1}}}, "emissive.gltf",
          {"material 0", "invalid emissiveFactor[2] -1"});
    check({{"emissiveFactor", {1, 1, 1}},
           {"extensions", {{"KHR_materials_emissive_strength", {{"emissiveStrength", -5}}}}}},
          "strength.gltf", {"material 0", "emissiveStrength -5", "finite and >= 0"});
    check({{"pbrMetallicRoughness", {{"metallicFactor", 2}}}}, "metallic.gltf",
          {"material 0", "invalid metallicFactor 2"});
    check({{"pbrMetallicRoughness", {{"roughnessFactor", -0.1}}}}, "roughness.gltf",
          {"material 0", "invalid roughnessFactor -0.1"});
    check({{"alphaMode", "GLASS"}}, "alphamode.gltf", {"material 0", "unknown alphaMode 'GLASS'"});
    check({{"alphaMode", "MASK"}, {"alphaCutoff", -1}}, "cutoff.gltf",
          {"material 0", "invalid alphaCutoff -1"});

    // Large strengths are legal (HDR emitters)
    Gltf g;
    g.material({{"emissiveFactor", {1, 0.5, 0}},
                {"extensions", {{"KHR_materials_emissive_strength", {{"emissiveStrength", 40}}}}}});
    TempDir dir;
    const Scene s = loadGltf(g.write(dir, "strong.gltf"));
    EXPECT_EQ(s.materials[0].emissiveFactor, glm::vec3(40, 20, 0));
}

// ---------------------------------------------------------------------------------------------
// 6. Non-finite vertices, degenerate and duplicate triangles
// ---------------------------------------------------------------------------------------------

TEST(CpuGltfHardening, NonFiniteVerticesNameTheAccessor) {
    const float inf = std::numeric_limits<float>::infinity();
    Gltf g;
    g.primitive()["attributes"]["POSITION"] =
        g.accessor(std::vector<float>{0, 0, 0, 1, 0, 0, 0, inf, 0}, kFloat, "VEC3", 3);
    expectLoadError(g, "inf.gltf",
                    {"mesh 'tri' primitive 0 POSITION (accessor 1)", "1 of 3 POSITION values",
                     "NaN or infinite", "element 2"});

    Gltf h;
    h.primitive()["attributes"]["NORMAL"] =
        h.accessor(std::vector<float>{0, 0, 1, std::nanf(""), 0, 1, 0, 0, 1}, kFloat, "VEC3", 3);
    expectLoadError(h, "nannormal.gltf", {"NORMAL (accessor 1)", "1 of 3 NORMAL values"});
}

TEST(CpuGltfHardening, DegenerateAndDuplicateTriangles) {
    Gltf g;
    const int pos = g.accessor(std::vector<float>{0, 0, 0, 1, 0, 0, 0, 1, 0, 2, 0, 0, 0, 0, 0},
                               kFloat, "VEC3", 5);
    g.primitive()["attributes"]["POSITION"] = pos;
    // good, its duplicate, a repeated index, collinear, two coincident vertices (zero area)
    g.primitive()["indices"] =
        g.accessor(std::vector<uint16_t>{0, 1, 2, 0, 1, 2, 0, 0, 2, 0, 1, 3, 0, 4, 1, 0}, kUShort,
                   "SCALAR", 15);
    TempDir dir;
    const Scene s = loadGltf(g.write(dir, "degenerate.gltf"));
    // Duplicates are legal geometry and kept; zero-area triangles are dropped (with a warning),
    // so nothing downstream divides by their area.
    EXPECT_EQ(s.triangleCount(), 2u);
    bool counted = false;
    for (const auto& w : s.warnings)
        counted |= w.find("dropped 3 degenerate") != std::string::npos;
    EXPECT_TRUE(counted);
    for (const Vertex& v : s.vertices) {
        EXPECT_TRUE(std::isfinite(v.normal.x + v.normal.y + v.normal.z));
        EXPECT_NEAR(glm::length(v.normal), 1.0f, 1e-5f);
    }

    Gltf flat;  // only degenerate triangles: nothing left to render is an error
    flat.primitive()["indices"] =
        flat.accessor(std::vector<uint16_t>{0, 0, 1, 0}, kUShort, "SCALAR", 3);
    expectLoadError(flat, "allflat.gltf", {"contains no triangles"});
}

}  // namespace

// Every file a glTF references must be a regular file: a buffer or image uri naming a folder
// failed with a bare std::bad_alloc, a FIFO would block (issue 48).
TEST(CpuGltfHardening, ExternalFilesMustBeRegularFiles) {
    TempDir dir;
    fs::create_directories(dir.path() / "folder");
    {  // a buffer
        Gltf g;
        g.write(dir, "embedded.gltf");
        g.doc["buffers"][0]["uri"] = "folder";
        const std::string path = dir.write("buffer.gltf", g.doc.dump());
        expectError([&] { loadGltf(path); },
                    {path + ": the uri \"folder\" (" + (dir.path() / "folder").string() +
                     ") is a folder, not a file"});
    }
    {  // an image, used or not
        Gltf g;
        g.doc["images"] = {{{"uri", "folder"}}};
        const std::string path = g.write(dir, "image.gltf");
        expectError([&] { loadGltf(path); },
                    {path + ": the uri \"folder\"", "is a folder, not a file"});
    }
    {  // a FIFO
        ASSERT_EQ(::mkfifo((dir.path() / "pipe").c_str(), 0600), 0);
        Gltf g;
        g.doc["images"] = {{{"uri", "pipe"}}};
        const std::string path = g.write(dir, "fifo.gltf");
        expectError([&] { loadGltf(path); },
                    {path + ": the uri \"pipe\"", "is not a regular file"});
    }
}
