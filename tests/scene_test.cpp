// Scene model tests (Cpu* suites): the shared glTF scenes, the procedural Cornell box, the
// camera's raster/ray consistency, the scene description files and every bad-input report.
#include <gtest/gtest.h>

#include "tests/temp_dir.h"

#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <tuple>

#include <unistd.h>

#include <glm/gtc/constants.hpp>
#include <nlohmann/json.hpp>

#include "core/scene/emission.h"
#include "core/scene/mesh_builder.h"
#include "core/scene/procedural_cornell.h"
#include "core/scene/procedural_rooms.h"
#include "core/scene/scene_loader.h"
#include "core/util/error.h"

using namespace gilab;
namespace fs = std::filesystem;
using nlohmann::json;

namespace {

const std::string kShared = GILAB_SHARED_SCENES_DIR;
const std::string kScenes = std::string(GILAB_SOURCE_DIR) + "/scenes";

// ---------------------------------------------------------------------------------------------
// Helpers
// ---------------------------------------------------------------------------------------------

/** Runs `fn`, expects a gilab::Error, and checks the message holds every given fragment. */
template <typename Fn>
void expectError(Fn&& fn, std::initializer_list<std::string> fragments) {
    try {
        fn();
        ADD_FAILURE() << "expected gilab::Error";
    } catch (const Error& e) {
        const std::string msg = e.what();
        for (const std::string& f : fragments) {
            EXPECT_NE(msg.find(f), std::string::npos) << "'" << f << "' not in: " << msg;
        }
    }
}

glm::vec3 geometricNormal(const Scene& s, size_t t) {
    const glm::vec3 a = s.vertices[s.indices[3 * t]].position;
    const glm::vec3 b = s.vertices[s.indices[3 * t + 1]].position;
    const glm::vec3 c = s.vertices[s.indices[3 * t + 2]].position;
    return glm::normalize(glm::cross(b - a, c - a));
}

float triangleArea(const Scene& s, size_t t) {
    const glm::vec3 a = s.vertices[s.indices[3 * t]].position;
    const glm::vec3 b = s.vertices[s.indices[3 * t + 1]].position;
    const glm::vec3 c = s.vertices[s.indices[3 * t + 2]].position;
    return 0.5f * glm::length(glm::cross(b - a, c - a));
}

glm::vec3 triangleCentre(const Scene& s, size_t t) {
    glm::vec3 c(0.0f);
    for (int k = 0; k < 3; ++k)
        c += s.vertices[s.indices[3 * t + size_t(k)]].position / 3.0f;
    return c;
}

int materialIndex(const Scene& s, const std::string& name) {
    for (size_t m = 0; m < s.materials.size(); ++m) {
        if (s.materials[m].name == name) return int(m);
    }
    return -1;
}

/** Each edge (by exact vertex positions) of the material's triangles, with its use count. */
std::map<std::pair<std::tuple<float, float, float>, std::tuple<float, float, float>>, int> edgeUses(
    const Scene& s, int material) {
    std::map<std::pair<std::tuple<float, float, float>, std::tuple<float, float, float>>, int> uses;
    auto key = [](const glm::vec3& p) { return std::make_tuple(p.x, p.y, p.z); };
    for (size_t t = 0; t < s.triangleCount(); ++t) {
        if (int(s.triangleMaterials[t]) != material) continue;
        for (int k = 0; k < 3; ++k) {
            auto a = key(s.vertices[s.indices[3 * t + size_t(k)]].position);
            auto b = key(s.vertices[s.indices[3 * t + size_t((k + 1) % 3)]].position);
            ++uses[std::minmax(a, b)];
        }
    }
    return uses;
}

bool isClosed(const Scene& s, int material) {
    const auto uses = edgeUses(s, material);
    if (uses.empty()) return false;
    for (const auto& item : uses) {
        if (item.second != 2) return false;
    }
    return true;
}

/** The nearest hit of the ray origin + t dir, t in (1e-7, tMax): its triangle (-1: none) and t. */
struct RayHit {
    int triangle = -1;
    double t = 0.0;
};

RayHit firstHit(const Scene& s, const glm::vec3& origin, const glm::vec3& dir, double tMax) {
    RayHit hit;
    hit.t = tMax;
    const glm::dvec3 o(origin), d(dir);
    for (size_t t = 0; t < s.triangleCount(); ++t) {
        // Moller-Trumbore, in double precision
        const glm::dvec3 a(s.vertices[s.indices[3 * t]].position);
        const glm::dvec3 e1 = glm::dvec3(s.vertices[s.indices[3 * t + 1]].position) - a;
        const glm::dvec3 e2 = glm::dvec3(s.vertices[s.indices[3 * t + 2]].position) - a;
        const glm::dvec3 p = glm::cross(d, e2);
        const double det = glm::dot(e1, p);
        if (std::abs(det) < 1e-15) continue;
        const glm::dvec3 q = o - a;
        const double u = glm::dot(q, p) / det;
        const glm::dvec3 r = glm::cross(q, e1);
        const double v = glm::dot(d, r) / det;
        const double dist = glm::dot(e2, r) / det;
        if (u < 0.0 || v < 0.0 || u + v > 1.0 || dist <= 1e-7 || dist >= hit.t) continue;
        hit.triangle = int(t);
        hit.t = dist;
    }
    return hit;
}

/** This file's temporary folders (tests/temp_dir.h). */
class TempDir : public test::TempDir {
public:
    TempDir() : test::TempDir("gilab_scene_test") {}
};

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

/** Builds tiny glTF files by hand: one buffer, one bufferView per accessor. */
class GltfBuilder {
public:
    GltfBuilder() {
        doc = {{"asset", {{"version", "2.0"}}},
               {"scenes", {{{"nodes", {0}}}}},
               {"scene", 0},
               {"nodes", {{{"mesh", 0}}}},
               {"meshes", json::array()},
               {"accessors", json::array()},
               {"bufferViews", json::array()}};
    }
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
    int positions(const std::vector<float>& xyz) {
        return accessor(xyz, 5126, "VEC3", xyz.size() / 3);
    }
    int indices(const std::vector<uint16_t>& idx) {
        return accessor(idx, 5123, "SCALAR", idx.size());
    }
    /** Adds mesh 0 with one primitive; attributes beyond POSITION are optional. */
    void mesh(int position, int indexAccessor = -1, int material = -1) {
        json prim = {{"attributes", {{"POSITION", position}}}};
        if (indexAccessor >= 0) prim["indices"] = indexAccessor;
        if (material >= 0) prim["material"] = material;
        doc["meshes"].push_back({{"name", "testMesh"}, {"primitives", {prim}}});
    }
    std::string writeGltf(const TempDir& dir, const std::string& name) {
        doc["buffers"] = {{{"byteLength", m_bin.size()},
                           {"uri", "data:application/octet-stream;base64," + base64(m_bin)}}};
        return dir.write(name, doc.dump(2));
    }
    std::string writeGlb(const TempDir& dir, const std::string& name) {
        doc["buffers"] = {{{"byteLength", m_bin.size()}}};
        std::string text = doc.dump();
        while (text.size() % 4)
            text.push_back(' ');
        auto u32 = [](uint32_t v) { return std::string(reinterpret_cast<const char*>(&v), 4); };
        const uint32_t total = uint32_t(12 + 8 + text.size() + 8 + m_bin.size());
        const std::string glb = "glTF" + u32(2) + u32(total) + u32(uint32_t(text.size())) + "JSON" +
                                text + u32(uint32_t(m_bin.size())) + std::string("BIN\0", 4) +
                                m_bin;
        return dir.write(name, glb);
    }
    json doc;

private:
    std::string m_bin;
};

/** Triangle in the z = 0 plane plus a unit square, indexed. */
GltfBuilder twoPrimitiveQuad() {
    GltfBuilder b;
    const int pos = b.positions({0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0});
    b.mesh(pos, b.indices({0, 1, 2, 0, 2, 3}));
    return b;
}

// ---------------------------------------------------------------------------------------------
// The shared glTF scenes (each loaded once)
// ---------------------------------------------------------------------------------------------

class CpuSharedScenes : public ::testing::Test {
protected:
    static void SetUpTestSuite() {
        if (!fs::exists(kShared + "/cornell-box/cornell_box.gltf")) return;
        s_cornell = std::make_unique<Scene>(loadGltf(kShared + "/cornell-box/cornell_box.gltf"));
        s_sponza = std::make_unique<Scene>(loadGltf(kShared + "/dabrovic-sponza/sponza.gltf"));
        s_sibenik = std::make_unique<Scene>(loadGltf(kShared + "/sibenik/sibenik.gltf"));
    }
    static void TearDownTestSuite() {
        s_cornell.reset();
        s_sponza.reset();
        s_sibenik.reset();
    }
    void SetUp() override {
        if (!s_cornell) GTEST_SKIP() << "shared scenes not found at " << kShared;
    }
    static void expectBounds(const Scene& s, glm::vec3 lo, glm::vec3 hi, float tol) {
        for (int k = 0; k < 3; ++k) {
            EXPECT_NEAR(s.caps.bounds.lo[k], lo[k], tol) << s.name << " axis " << k;
            EXPECT_NEAR(s.caps.bounds.hi[k], hi[k], tol) << s.name << " axis " << k;
        }
    }
    static std::unique_ptr<Scene> s_cornell, s_sponza, s_sibenik;
};
std::unique_ptr<Scene> CpuSharedScenes::s_cornell, CpuSharedScenes::s_sponza,
    CpuSharedScenes::s_sibenik;

TEST_F(CpuSharedScenes, CornellBoxGltf) {
    // The README's 36 counts the source OBJ's 18 quads; the glTF export has 32 triangles.
    const Scene& s = *s_cornell;
    EXPECT_EQ(s.triangleCount(), 32u);
    EXPECT_EQ(s.materials.size(), 8u);
    expectBounds(s, {-1.0f, 0.0f, -1.0f}, {1.0f, 1.99f, 1.0f}, 0.05f);
    EXPECT_EQ(s.caps.emissiveTriangleCount, 2u);
    const int light = materialIndex(s, "light");
    ASSERT_GE(light, 0);
    const glm::vec3 e = s.materials[size_t(light)].emissiveFactor;  // 1,0.706,0.235 x 17
    EXPECT_NEAR(e.x, 17.0f, 1e-4f);
    EXPECT_NEAR(e.y, 12.0f, 1e-3f);
    EXPECT_NEAR(e.z, 4.0f, 1e-3f);
    EXPECT_FALSE(s.caps.hasGlossy);
    EXPECT_FALSE(s.caps.hasTextures);
    EXPECT_EQ(s.loadedFiles.size(), 2u);  // .gltf + .bin
    for (const Vertex& v : s.vertices)
        EXPECT_NEAR(glm::length(v.normal), 1.0f, 1e-4f);
}

TEST_F(CpuSharedScenes, Sponza) {
    // README: 66,450 in the source 3DS; the glTF holds 66,440, one of them zero-area.
    const Scene& s = *s_sponza;
    EXPECT_EQ(s.triangleCount(), 66439u);
    bool warned = false;
    for (const auto& w : s.warnings)
        warned |= w.find("dropped 1 degenerate") != w.npos;
    EXPECT_TRUE(warned);
    expectBounds(s, {-17.4f, -0.9f, -7.8f}, {17.4f, 15.7f, 7.8f}, 0.1f);
    EXPECT_EQ(s.materials.size(), 20u);
    EXPECT_EQ(s.textures.size(), 11u);  // 18 glTF textures over 11 JPEG images
    EXPECT_TRUE(s.caps.hasTextures);
    EXPECT_FALSE(s.caps.hasEmissive);
    EXPECT_EQ(s.loadedFiles.size(), 13u);  // .gltf, .bin, 11 images
}

TEST_F(CpuSharedScenes, Sibenik) {
    // README: 76,529 in the source 3DS; the glTF holds 76,505, one of them zero-area.
    const Scene& s = *s_sibenik;
    EXPECT_EQ(s.triangleCount(), 76504u);
    EXPECT_EQ(s.materials.size(), 11u);
    EXPECT_EQ(s.textures.size(), 3u);
    EXPECT_TRUE(s.caps.hasAlphaMask);  // the BLEND glass, loaded as MASK
    const int glas = materialIndex(s, "glas");
    ASSERT_GE(glas, 0);
    EXPECT_EQ(s.materials[size_t(glas)].alphaMode, AlphaMode::Mask);
    // The file includes the surrounding ground; the cathedral (its floor) sits inside it.
    EXPECT_NEAR(s.caps.bounds.hi.y, 28.7f, 0.05f);
    Bounds floor;
    const int pod = materialIndex(s, "pod");
    for (size_t t = 0; t < s.triangleCount(); ++t) {
        if (int(s.triangleMaterials[t]) == pod) floor.extend(triangleCentre(s, t));
    }
    EXPECT_GT(floor.lo.x, -11.8f);
    EXPECT_LT(floor.hi.x, 26.0f);
    EXPECT_GT(floor.lo.z, -8.0f);
    EXPECT_LT(floor.hi.z, 8.0f);
}

TEST_F(CpuSharedScenes, TextureTexelsMatchOpenImageIO) {
    // Lossless PNG: every texel must match an independent decode exactly.
    const Texture* tex = nullptr;
    for (const Texture& t : s_sibenik->textures) {
        if (t.name.find("KAMEN31.png") != std::string::npos) tex = &t;
    }
    ASSERT_NE(tex, nullptr);
    EXPECT_EQ(tex->colorSpace, ColorSpace::Srgb);
    auto in = OIIO::ImageInput::open(tex->name);
    ASSERT_TRUE(in);
    const int channels = in->spec().nchannels;
    ASSERT_EQ(in->spec().width, tex->width);
    ASSERT_EQ(in->spec().height, tex->height);
    std::vector<uint8_t> pixels(size_t(tex->width) * size_t(tex->height) * size_t(channels));
    ASSERT_TRUE(in->read_image(0, 0, 0, channels, OIIO::TypeDesc::UINT8, pixels.data()));
    size_t mismatches = 0;
    for (size_t p = 0; p < size_t(tex->width) * size_t(tex->height); ++p) {
        for (int c = 0; c < 3; ++c) {
            mismatches += pixels[p * size_t(channels) + size_t(c)] != tex->rgba[p * 4 + size_t(c)];
        }
        mismatches += tex->rgba[p * 4 + 3] != 255;
    }
    EXPECT_EQ(mismatches, 0u);
    EXPECT_EQ(tex->rgba[0], 172);  // the top-left texel, row 0 = top of the image
    EXPECT_EQ(tex->rgba[1], 150);
    EXPECT_EQ(tex->rgba[2], 139);
}

// ---------------------------------------------------------------------------------------------
// Procedural Cornell box
// ---------------------------------------------------------------------------------------------

TEST(CpuCornellBox, DefaultGeometryAndCaps) {
    const Scene s = makeCornellBox({});
    EXPECT_EQ(s.triangleCount(), 32u);  // 5 walls, 2 blocks x 5 faces, the light
    EXPECT_EQ(s.materials.size(), 8u);
    EXPECT_TRUE(s.caps.hasEmissive);
    EXPECT_EQ(s.caps.emissiveTriangleCount, 2u);
    EXPECT_FALSE(s.caps.hasGlossy);
    EXPECT_NEAR(s.caps.bounds.hi.x, 0.556f, 1e-6f);
    EXPECT_NEAR(s.caps.bounds.hi.y, 0.5488f, 1e-6f);
    EXPECT_NEAR(s.caps.bounds.hi.z, 0.5592f, 1e-6f);
    for (const Material& m : s.materials) {
        EXPECT_FALSE(m.name.empty());
        EXPECT_EQ(m.metallic, 0.0f);
        EXPECT_EQ(m.roughness, 1.0f);
    }
    const int red = materialIndex(s, "leftWall");
    ASSERT_GE(red, 0);
    EXPECT_EQ(glm::vec3(s.materials[size_t(red)].baseColorFactor), glm::vec3(0.63f, 0.065f, 0.05f));
    EXPECT_NEAR(s.camera.vfovRad, glm::radians(39.3f), 1e-6f);
    EXPECT_EQ(s.camera.position, glm::vec3(0.278f, 0.273f, -0.8f));

    CornellBoxParams dark;
    dark.light = false;
    const Scene d = makeCornellBox(dark);
    EXPECT_EQ(d.triangleCount(), 30u);
    EXPECT_FALSE(d.caps.hasEmissive);
}

TEST(CpuCornellBox, NormalsUnitAndFacing) {
    const Scene s = makeCornellBox({});
    const glm::vec3 roomCentre = 0.5f * kCornellRoomSize;
    for (size_t t = 0; t < s.triangleCount(); ++t) {
        const std::string& name = s.materials[s.triangleMaterials[t]].name;
        const glm::vec3 g = geometricNormal(s, t);
        for (int k = 0; k < 3; ++k) {
            const glm::vec3 n = s.vertices[s.indices[3 * t + size_t(k)]].normal;
            EXPECT_NEAR(glm::length(n), 1.0f, 1e-5f);
            EXPECT_GT(glm::dot(n, g), 0.999f) << name << ": winding disagrees with the normal";
        }
        const glm::vec3 c = triangleCentre(s, t);
        if (name == "light") {
            EXPECT_GT(-g.y, 0.999f);
        } else if (name == "shortBox" || name == "tallBox") {
            glm::vec3 blockCentre(0.0f);  // outward: away from the block's own centroid
            float count = 0.0f;
            for (size_t u = 0; u < s.triangleCount(); ++u) {
                if (s.triangleMaterials[u] == s.triangleMaterials[t]) {
                    blockCentre += triangleCentre(s, u);
                    count += 1.0f;
                }
            }
            EXPECT_GT(glm::dot(g, c - blockCentre / count), 0.0f) << name;
        } else {
            EXPECT_GT(glm::dot(g, roomCentre - c), 0.0f) << name << " faces out of the box";
        }
    }
}

TEST(CpuCornellBox, LightAreaAndRadiance) {
    for (float size : {1.0f, 2.0f}) {
        CornellBoxParams p;
        p.lightSize = size;
        p.lightRadiance = {1.0f, 2.0f, 3.0f};
        const Scene s = makeCornellBox(p);
        const int light = materialIndex(s, "light");
        float area = 0.0f;
        for (size_t t = 0; t < s.triangleCount(); ++t) {
            if (int(s.triangleMaterials[t]) == light) {
                area += triangleArea(s, t);
                EXPECT_NEAR(triangleCentre(s, t).y, 0.5488f - p.lightOffset, 1e-6f);
            }
        }
        EXPECT_NEAR(area, 0.130f * 0.105f * size * size, 1e-6f);
        EXPECT_EQ(s.materials[size_t(light)].emissiveFactor, glm::vec3(1.0f, 2.0f, 3.0f));
    }
}

TEST(CpuCornellBox, ThickWallsAreClosedSlabs) {
    CornellBoxParams p;
    p.wallThickness = 0.02f;
    p.frontWall = true;
    p.opening = glm::vec4(0.3f, 0.4f, 0.6f, 0.8f);
    const Scene s = makeCornellBox(p);
    for (const char* wall :
         {"floor", "ceiling", "backWall", "leftWall", "rightWall", "frontWall"}) {
        EXPECT_TRUE(isClosed(s, materialIndex(s, wall))) << wall;
    }
    // A window touching the floor (a door) keeps the slab closed too.
    p.opening = glm::vec4(0.4f, 0.0f, 0.6f, 0.5f);
    EXPECT_TRUE(isClosed(makeCornellBox(p), materialIndex(makeCornellBox(p), "backWall")));
}

TEST(CpuCornellBox, ClosedRoomWithoutThickness) {
    CornellBoxParams p;
    p.frontWall = true;
    p.blocks = false;
    p.light = false;
    Scene s = makeCornellBox(p);
    for (uint32_t& m : s.triangleMaterials)
        m = 0;  // one surface: every edge shared twice
    EXPECT_TRUE(isClosed(s, 0));
    EXPECT_GT(s.camera.position.z, 0.0f);  // the camera moved inside
}

TEST(CpuCornellBox, OpeningCutsTheBackWall) {
    CornellBoxParams p;
    p.opening = glm::vec4(0.25f, 0.3f, 0.75f, 0.7f);
    const Scene s = makeCornellBox(p);
    const int back = materialIndex(s, "backWall");
    float area = 0.0f;
    for (size_t t = 0; t < s.triangleCount(); ++t) {
        if (int(s.triangleMaterials[t]) == back) area += triangleArea(s, t);
    }
    const float full = kCornellRoomSize.x * kCornellRoomSize.y;
    EXPECT_NEAR(area, full * (1.0f - 0.5f * 0.4f), 1e-6f);
}

TEST(CpuCornellBox, AlbedoScaleClampsAndRejectsNegative) {
    CornellBoxParams p;
    p.albedoScale = 2.0f;
    const Scene s = makeCornellBox(p);
    const glm::vec4 white = s.materials[size_t(materialIndex(s, "floor"))].baseColorFactor;
    EXPECT_EQ(glm::vec3(white), glm::vec3(1.0f));
    const glm::vec4 red = s.materials[size_t(materialIndex(s, "leftWall"))].baseColorFactor;
    EXPECT_NEAR(red.y, 0.13f, 1e-6f);
    p.albedoScale = -1.0f;
    expectError([&] { makeCornellBox(p); }, {"cornell_box", "albedo_scale"});
}

// ---------------------------------------------------------------------------------------------
// Procedural two rooms joined by a door
// ---------------------------------------------------------------------------------------------

std::string hitMaterial(const Scene& s, const RayHit& hit) {
    return hit.triangle < 0 ? "(nothing)"
                            : s.materials[s.triangleMaterials[size_t(hit.triangle)]].name;
}

TEST(CpuTwoRooms, DefaultGeometryAndCaps) {
    const Scene s = makeTwoRooms({});
    EXPECT_EQ(s.name, "two_rooms");
    // Shell 6 quads; slab 5 wall cells x 2 faces + 12 rim quads (the door reaches the floor)
    EXPECT_EQ(s.triangleCount(), 2u * (6u + 10u + 12u));
    EXPECT_EQ(s.materials.size(), 7u);
    EXPECT_FALSE(s.caps.hasEmissive);
    EXPECT_TRUE(s.lights.empty());
    EXPECT_NEAR(s.caps.bounds.lo.x, 0.0f, 1e-6f);
    EXPECT_NEAR(s.caps.bounds.lo.y, 0.0f, 1e-6f);
    EXPECT_NEAR(s.caps.bounds.lo.z, 0.0f, 1e-6f);
    EXPECT_NEAR(s.caps.bounds.hi.x, 1.02f, 1e-6f);  // two 0.5 m rooms and the 2 cm wall
    EXPECT_NEAR(s.caps.bounds.hi.y, 0.5f, 1e-6f);
    EXPECT_NEAR(s.caps.bounds.hi.z, 0.5f, 1e-6f);
    const int red = materialIndex(s, "farWallA");
    ASSERT_GE(red, 0);
    EXPECT_EQ(glm::vec3(s.materials[size_t(red)].baseColorFactor), glm::vec3(0.63f, 0.065f, 0.05f));
    EXPECT_EQ(glm::vec3(s.materials[size_t(materialIndex(s, "divider"))].baseColorFactor),
              glm::vec3(0.7f));
    for (const Material& m : s.materials) {
        EXPECT_EQ(m.metallic, 0.0f) << m.name;
        EXPECT_EQ(m.roughness, 1.0f) << m.name;
    }
    // The camera is in room B, looking at the divider (towards -x)
    const TwoRoomsLayout layout = twoRoomsLayout({});
    EXPECT_GT(s.camera.position.x, layout.roomB.lo.x);
    EXPECT_LT(s.camera.position.x, layout.roomB.hi.x);
    EXPECT_LT(s.camera.target.x, s.camera.position.x);
}

TEST(CpuTwoRooms, NormalsFaceIntoTheRoomsAndTheSlabIsClosed) {
    for (const glm::vec4& door :
         {glm::vec4(0.35f, 0.0f, 0.65f, 0.6f), glm::vec4(0.2f, 0.1f, 0.5f, 0.7f)}) {
        for (bool open : {true, false}) {
            TwoRoomsParams p;
            p.door = door;
            p.doorOpen = open;
            const Scene s = makeTwoRooms(p);
            const int divider = materialIndex(s, "divider");
            EXPECT_TRUE(isClosed(s, divider)) << "door " << open;
            const glm::vec3 centre = s.caps.bounds.center();
            for (size_t t = 0; t < s.triangleCount(); ++t) {
                const glm::vec3 g = geometricNormal(s, t);
                for (int k = 0; k < 3; ++k)
                    EXPECT_GT(glm::dot(s.vertices[s.indices[3 * t + size_t(k)]].normal, g), 0.999f);
                if (int(s.triangleMaterials[t]) == divider) continue;
                EXPECT_GT(glm::dot(g, centre - triangleCentre(s, t)), 0.0f)
                    << s.materials[s.triangleMaterials[t]].name << " faces out";
            }
        }
    }
    TwoRoomsParams closed;
    closed.doorOpen = false;
    EXPECT_EQ(makeTwoRooms(closed).triangleCount(), 2u * (6u + 2u + 4u));
}

TEST(CpuTwoRooms, DoorAreaAndBadParameters) {
    TwoRoomsParams p;
    p.roomSize = {0.4f, 0.3f, 0.6f};
    const Scene s = makeTwoRooms(p);
    const int divider = materialIndex(s, "divider");
    float area = 0.0f;
    for (size_t t = 0; t < s.triangleCount(); ++t)
        if (int(s.triangleMaterials[t]) == divider) area += triangleArea(s, t);
    // Each face: the 0.6 x 0.3 wall less the 0.18 x 0.18 door. The 2 cm rims: the wall's outline
    // less the door's sill (the floor closes it), plus two 0.18 jambs and the 0.18 lintel.
    const float face = 0.6f * 0.3f - 0.18f * 0.18f;
    const float rims = 0.02f * ((2.0f * 0.6f + 2.0f * 0.3f - 0.18f) + 3.0f * 0.18f);
    EXPECT_NEAR(area, 2.0f * face + rims, 1e-5f);
    const TwoRoomsLayout layout = twoRoomsLayout(p);
    EXPECT_NEAR(layout.door.lo.z, 0.21f, 1e-6f);
    EXPECT_NEAR(layout.door.hi.z, 0.39f, 1e-6f);
    EXPECT_NEAR(layout.door.hi.y, 0.18f, 1e-6f);
    EXPECT_NEAR(layout.roomB.hi.x, 0.82f, 1e-6f);

    TwoRoomsParams bad;
    bad.wallThickness = 0.0f;
    expectError([&] { makeTwoRooms(bad); }, {"two_rooms", "wall_thickness"});
    bad = {};
    bad.roomSize.y = -1.0f;
    expectError([&] { makeTwoRooms(bad); }, {"two_rooms", "room_size"});
    bad = {};
    bad.door = {0.5f, 0.0f, 0.4f, 0.6f};
    expectError([&] { makeTwoRooms(bad); }, {"two_rooms", "door"});
    bad = {};
    bad.red = glm::vec3(1.5f, 0.0f, 0.0f);
    expectError([&] { makeTwoRooms(bad); }, {"two_rooms", "red"});
}

// ---------------------------------------------------------------------------------------------
// Camera: the rasteriser (view/projection) and the path tracer (primaryRay) agree
// ---------------------------------------------------------------------------------------------

TEST(CpuCamera, CentreRayIsForward) {
    Camera cam;
    cam.position = {1.0f, 2.0f, 3.0f};
    cam.target = {-2.0f, 0.5f, -4.0f};
    const Ray r = cam.primaryRay(64.0f, 36.0f, 128, 72);
    EXPECT_LT(glm::length(r.direction - cam.forward()), 1e-6f);
    EXPECT_EQ(r.origin, cam.position);
}

TEST(CpuCamera, ProjectionMatchesPrimaryRays) {
    Camera cam;
    cam.position = {0.3f, 1.2f, 2.5f};
    cam.target = {-0.4f, 0.8f, -1.0f};
    cam.vfovRad = glm::radians(50.0f);
    const int width = 160, height = 90;
    const glm::mat4 viewProj = cam.projection(float(width) / float(height)) * cam.view();
    for (int y : {0, 7, 45, 89}) {
        for (int x : {0, 33, 80, 159}) {
            const Ray r = cam.primaryRay(x + 0.5f, y + 0.5f, width, height);
            const glm::vec4 clip = viewProj * glm::vec4(r.origin + 3.7f * r.direction, 1.0f);
            const glm::vec3 ndc = glm::vec3(clip) / clip.w;
            EXPECT_NEAR((ndc.x + 1.0f) * 0.5f * width, x + 0.5f, 1e-3f);
            EXPECT_NEAR((ndc.y + 1.0f) * 0.5f * height, y + 0.5f, 1e-3f);  // y down
            EXPECT_GT(ndc.z, 0.0f);
            EXPECT_LT(ndc.z, 1.0f);
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Scene description files
// ---------------------------------------------------------------------------------------------

TEST(CpuSceneFile, CornellBoxJsonIsTheBuiltinDefault) {
    const Scene file = loadSceneFile(kScenes + "/cornell_box.json");
    const Scene builtin = makeBuiltinDefaultScene();
    EXPECT_EQ(file.name, "cornell_box");
    EXPECT_EQ(builtin.name, "cornell_box");
    EXPECT_EQ(file.sourcePath, kScenes + "/cornell_box.json");
    ASSERT_EQ(file.loadedFiles.size(), 1u);
    ASSERT_EQ(file.vertices.size(), builtin.vertices.size());
    for (size_t i = 0; i < file.vertices.size(); ++i) {
        EXPECT_EQ(file.vertices[i].position, builtin.vertices[i].position);
    }
    EXPECT_EQ(file.indices, builtin.indices);
    EXPECT_EQ(file.triangleMaterials, builtin.triangleMaterials);
    EXPECT_EQ(file.camera.position, builtin.camera.position);
    EXPECT_EQ(file.settings.width, 128);
    EXPECT_EQ(builtin.settings.height, 128);
    EXPECT_TRUE(builtin.caps.hasEmissive);
    EXPECT_TRUE(builtin.lights.empty());
}

TEST(CpuSceneFile, CornellBoxVariants) {
    const Scene spot = loadSceneFile(kScenes + "/cornell_box.json#spot");
    EXPECT_EQ(spot.name, "cornell_box#spot");
    EXPECT_FALSE(spot.caps.hasEmissive);
    ASSERT_EQ(spot.lights.size(), 1u);
    EXPECT_TRUE(spot.caps.hasSpotLights);
    EXPECT_EQ(spot.lights[0].direction, glm::vec3(0.0f, -1.0f, 0.0f));
    EXPECT_NEAR(spot.lights[0].outerConeRad, glm::radians(60.0f), 1e-6f);
    const Scene point = loadSceneFile(kScenes + "/cornell_box.json", "point");
    EXPECT_TRUE(point.caps.hasPointLights);
    EXPECT_FALSE(point.caps.hasEmissive);
    expectError([] { loadSceneFile(kScenes + "/cornell_box.json#spot", "point"); },
                {"cornell_box.json", "variant given twice"});
}

/** The documented calibration: the spot gives the floor point below it the area light's E. */
TEST(CpuSceneFile, CornellSpotMatchesAreaLightIrradiance) {
    const Scene area = makeBuiltinDefaultScene();
    const Scene spot = loadSceneFile(kScenes + "/cornell_box.json#spot");
    const Light& l = spot.lights.at(0);
    const glm::vec3 floorPoint(l.position.x, 0.0f, l.position.z);
    const glm::vec3 eSpot = l.intensity / (l.position.y * l.position.y);
    // Integrate L cos cos' / r^2 over the emitter quad (midpoint rule, 200 x 200 cells).
    const int light = materialIndex(area, "light");
    Bounds quad;
    for (size_t t = 0; t < area.triangleCount(); ++t) {
        if (int(area.triangleMaterials[t]) != light) continue;
        for (int k = 0; k < 3; ++k)
            quad.extend(area.vertices[area.indices[3 * t + size_t(k)]].position);
    }
    const int n = 200;
    const glm::vec3 e = quad.extent();
    double sum = 0.0;
    for (int i = 0; i < n; ++i) {
        for (int j = 0; j < n; ++j) {
            const glm::vec3 p =
                quad.lo + glm::vec3((i + 0.5f) / n * e.x, 0.0f, (j + 0.5f) / n * e.z);
            const glm::vec3 d = p - floorPoint;
            const double r2 = glm::dot(d, d), cosine = d.y / std::sqrt(r2);
            sum += cosine * cosine / r2;
        }
    }
    const double eArea = sum * (e.x / n) * (e.z / n);  // per unit radiance
    const glm::vec3 radiance = area.materials[size_t(light)].emissiveFactor;
    for (int c = 0; c < 3; ++c)
        EXPECT_NEAR(eSpot[c] / (radiance[c] * eArea), 1.0, 0.01) << c;
}

TEST(CpuSceneFile, EveryFileAndVariantLoads) {
    if (!fs::exists(kShared)) GTEST_SKIP() << "shared scenes not found";
    for (const auto& entry : fs::directory_iterator(kScenes)) {
        if (entry.path().extension() != ".json") continue;
        std::ifstream in(entry.path());
        const json doc = json::parse(in);
        std::vector<std::string> variants = {""};
        if (doc.contains("variants")) {
            for (const auto& item : doc["variants"].items())
                variants.push_back(item.key());
        }
        for (const std::string& v : variants) {
            SCOPED_TRACE(entry.path().string() + "#" + v);
            const Scene s = loadSceneFile(entry.path().string(), v);
            EXPECT_GT(s.triangleCount(), 0u);
            EXPECT_TRUE(s.caps.hasEmissive || !s.lights.empty()) << "scene has no light";
            EXPECT_GT(glm::length(s.camera.target - s.camera.position), 0.0f);
            for (const std::string& w : s.warnings) {
                EXPECT_EQ(w.find("no camera"), std::string::npos) << w;
            }
        }
    }
}

TEST(CpuSceneFile, OverridesAndRelativePaths) {
    TempDir dir;
    fs::create_directories(dir.path("sub"));
    twoPrimitiveQuad().writeGltf(dir, "sub/quad.gltf");
    const std::string path = dir.write("scene.json", R"({
        "gltf": "sub/quad.gltf",
        "camera": {"position": [0.5, 0.5, 2], "target": [0.5, 0.5, 0], "vfov_deg": 30},
        "resolution": [64, 32],
        "exposure_ev": -1.5,
        "lights": [{"type": "directional", "direction": [0, 0, -2], "intensity": 3}],
        "extra_lights": [{"type": "spot", "position": [0, 0, 1], "target": [0, 0, 0],
                          "color": [1, 0.5, 0], "intensity": 2, "outer_cone_deg": 30}],
        "material_overrides": {"default": {"base_color": [0.2, 0.3, 0.4], "roughness": 0.5,
                                           "emissive": [1, 1, 1]}},
        "variants": {"dark": {"remove_emissive": true, "camera": {"vfov_deg": 20},
                              "extra_lights": null}}
    })");
    const Scene s = loadSceneFile(path);
    EXPECT_EQ(s.name, "scene");
    EXPECT_EQ(s.settings.width, 64);
    EXPECT_EQ(s.settings.height, 32);
    EXPECT_EQ(s.settings.exposureEv, -1.5f);
    ASSERT_EQ(s.lights.size(), 2u);
    EXPECT_EQ(s.lights[0].direction, glm::vec3(0.0f, 0.0f, -1.0f));
    EXPECT_EQ(s.lights[1].intensity, glm::vec3(2.0f, 1.0f, 0.0f));
    EXPECT_NEAR(s.lights[1].outerConeRad, glm::radians(30.0f), 1e-6f);
    EXPECT_EQ(s.materials.at(0).baseColorFactor, glm::vec4(0.2f, 0.3f, 0.4f, 1.0f));
    EXPECT_TRUE(s.caps.hasGlossy);
    EXPECT_TRUE(s.caps.hasEmissive);
    EXPECT_NEAR(s.camera.vfovRad, glm::radians(30.0f), 1e-6f);
    EXPECT_EQ(s.loadedFiles.at(0), path);
    EXPECT_EQ(s.loadedFiles.at(1), dir.path("sub/quad.gltf"));

    const Scene dark = loadSceneFile(path + "#dark");  // merged over the base
    EXPECT_EQ(dark.name, "scene#dark");
    EXPECT_FALSE(dark.caps.hasEmissive);
    EXPECT_EQ(dark.lights.size(), 1u);  // null removed extra_lights
    EXPECT_NEAR(dark.camera.vfovRad, glm::radians(20.0f), 1e-6f);
    EXPECT_EQ(dark.camera.position, glm::vec3(0.5f, 0.5f, 2.0f));
}

TEST(CpuSceneFile, DefaultCameraFramesTheBounds) {
    TempDir dir;
    twoPrimitiveQuad().writeGltf(dir, "quad.gltf");
    const std::string path = dir.write("s.json", R"({"gltf": "quad.gltf"})");
    const Scene s = loadSceneFile(path);
    ASSERT_EQ(s.warnings.size(), 1u);
    EXPECT_NE(s.warnings[0].find("no camera"), std::string::npos);
    EXPECT_LT(glm::length(s.camera.target - glm::vec3(0.5f, 0.5f, 0.0f)), 1e-5f);
}

const std::string kTwoRooms = kScenes + "/stress/two_rooms_door.json";

TEST(CpuSceneFile, TwoRoomsDoorLoads) {
    const Scene s = loadSceneFile(kTwoRooms);
    EXPECT_EQ(s.name, "two_rooms_door");
    EXPECT_EQ(s.triangleCount(), makeTwoRooms({}).triangleCount());
    EXPECT_NEAR(s.caps.bounds.hi.x - s.caps.bounds.lo.x, 1.02f, 1e-6f);
    EXPECT_NEAR(s.caps.bounds.hi.y - s.caps.bounds.lo.y, 0.5f, 1e-6f);
    EXPECT_NEAR(s.caps.bounds.hi.z - s.caps.bounds.lo.z, 0.5f, 1e-6f);
    EXPECT_EQ(s.settings.width, 64);
    EXPECT_EQ(s.settings.height, 64);
    ASSERT_EQ(s.lights.size(), 1u);
    EXPECT_EQ(s.lights[0].type, LightType::Spot);
    const TwoRoomsLayout layout = twoRoomsLayout({});
    auto inside = [](const Bounds& b, const glm::vec3& p) {
        return glm::all(glm::greaterThan(p, b.lo)) && glm::all(glm::lessThan(p, b.hi));
    };
    EXPECT_TRUE(inside(layout.roomA, s.lights[0].position));
    EXPECT_TRUE(inside(layout.roomB, s.camera.position));
    const Scene closed = loadSceneFile(kTwoRooms + "#closed");
    EXPECT_EQ(closed.name, "two_rooms_door#closed");
    EXPECT_LT(closed.triangleCount(), s.triangleCount());
}

/** Room B is lit only through the door: the spot's cone misses the whole opening. */
TEST(CpuSceneFile, TwoRoomsDoorSpotMissesTheDoor) {
    const Scene s = loadSceneFile(kTwoRooms);
    const Light& l = s.lights.at(0);
    const Bounds door = twoRoomsLayout({}).door;
    float minAngle = glm::pi<float>();
    const int n = 64;
    for (int i = 0; i <= n; ++i) {
        for (int j = 0; j <= n; ++j) {
            for (float x : {door.lo.x, door.hi.x}) {
                const glm::vec3 p(x, door.lo.y + door.extent().y * float(j) / n,
                                  door.lo.z + door.extent().z * float(i) / n);
                const float c = glm::dot(glm::normalize(p - l.position), l.direction);
                minAngle = std::min(minAngle, std::acos(std::clamp(c, -1.0f, 1.0f)));
            }
        }
    }
    EXPECT_GT(minAngle, l.outerConeRad + glm::radians(2.0f));
    // ...and it does light room A's floor next to the door
    const RayHit axis = firstHit(s, l.position, l.direction, 10.0);
    ASSERT_GE(axis.triangle, 0);
    EXPECT_EQ(hitMaterial(s, axis), "floor");
    const glm::vec3 spotOnFloor = l.position + float(axis.t) * l.direction;
    EXPECT_LT(door.lo.x - spotOnFloor.x, 0.25f);
}

/** A ray from room A through the door reaches room B; with the door closed the slab stops it. */
TEST(CpuSceneFile, TwoRoomsDoorLeavesAnOpening) {
    const TwoRoomsLayout layout = twoRoomsLayout({});
    const glm::vec3 doorCentre = layout.door.center();
    const Scene open = loadSceneFile(kTwoRooms);
    const Scene closed = loadSceneFile(kTwoRooms + "#closed");

    // Level with the door's centre: straight across to room B's far wall
    const glm::vec3 start(layout.roomA.center().x, doorCentre.y, doorCentre.z);
    const glm::vec3 across(1.0f, 0.0f, 0.0f);
    const RayHit a = firstHit(open, start, across, 10.0);
    EXPECT_EQ(hitMaterial(open, a), "farWallB");
    EXPECT_NEAR(start.x + float(a.t), layout.roomB.hi.x, 1e-5f);
    const RayHit b = firstHit(closed, start, across, 10.0);
    EXPECT_EQ(hitMaterial(closed, b), "divider");
    EXPECT_NEAR(start.x + float(b.t), layout.door.lo.x, 1e-5f);  // room A's face of the slab

    // From room A's centre through the door's centre: the first hit is inside room B
    const glm::vec3 centre = layout.roomA.center();
    const glm::vec3 dir = glm::normalize(doorCentre - centre);
    const RayHit c = firstHit(open, centre, dir, 10.0);
    ASSERT_GE(c.triangle, 0);
    EXPECT_GT((centre + float(c.t) * dir).x, layout.roomB.lo.x) << hitMaterial(open, c);
    const RayHit d = firstHit(closed, centre, dir, 10.0);
    EXPECT_EQ(hitMaterial(closed, d), "divider");
}

// ---------------------------------------------------------------------------------------------
// glTF features on tiny hand-built files
// ---------------------------------------------------------------------------------------------

TEST(CpuGltf, GlbHierarchyMirrorCameraAndLights) {
    GltfBuilder b;
    // Non-indexed triangle without normals, facing +z in its local space.
    b.mesh(b.positions({0, 0, 0, 1, 0, 0, 0, 1, 0}));
    b.doc["extensionsUsed"] = {"KHR_lights_punctual", "KHR_texture_transform"};
    b.doc["extensions"] = {{"KHR_lights_punctual",
                            {{"lights",
                              {{{"type", "spot"},
                                {"intensity", 5},
                                {"color", {1, 0.5, 0.25}},
                                {"spot", {{"outerConeAngle", 0.5}}}}}}}}};
    b.doc["cameras"] = {
        {{"type", "perspective"}, {"perspective", {{"yfov", 0.7}, {"znear", 0.1}, {"zfar", 50}}}}};
    // Parent: translate (10, 0, 0); child: mirror x. Camera and light rotated 90 deg about y.
    b.doc["nodes"] = {{{"children", {1, 2, 3}}, {"translation", {10, 0, 0}}},
                      {{"mesh", 0}, {"scale", {-1, 1, 1}}},
                      {{"camera", 0}, {"rotation", {0, 0.7071068, 0, 0.7071068}}},
                      {{"extensions", {{"KHR_lights_punctual", {{"light", 0}}}}},
                       {"rotation", {0, 0.7071068, 0, 0.7071068}},
                       {"translation", {0, 2, 0}}}};
    TempDir dir;
    const Scene s = loadGltf(b.writeGlb(dir, "tiny.glb"));
    ASSERT_EQ(s.triangleCount(), 1u);
    EXPECT_LT(glm::length(s.vertices[1].position - glm::vec3(9, 0, 0)), 1e-6f);
    // Mirrored: winding flipped so the computed normal and the winding agree (+z).
    EXPECT_GT(geometricNormal(s, 0).z, 0.999f);
    EXPECT_GT(s.vertices[0].normal.z, 0.999f);
    // -Z rotated +90 deg about y looks down -x.
    EXPECT_LT(glm::length(s.camera.forward() - glm::vec3(-1, 0, 0)), 1e-5f);
    EXPECT_LT(glm::length(s.camera.position - glm::vec3(10, 0, 0)), 1e-5f);
    EXPECT_NEAR(s.camera.vfovRad, 0.7f, 1e-6f);
    ASSERT_EQ(s.lights.size(), 1u);
    EXPECT_EQ(s.lights[0].type, LightType::Spot);
    EXPECT_LT(glm::length(s.lights[0].direction - glm::vec3(-1, 0, 0)), 1e-5f);
    EXPECT_LT(glm::length(s.lights[0].position - glm::vec3(10, 2, 0)), 1e-5f);
    EXPECT_EQ(s.lights[0].intensity, glm::vec3(5.0f, 2.5f, 1.25f));
    EXPECT_NEAR(s.lights[0].outerConeRad, 0.5f, 1e-6f);
    EXPECT_TRUE(s.caps.hasSpotLights);
    bool warned = false;  // used but unsupported extension
    for (const auto& w : s.warnings)
        warned |= w.find("KHR_texture_transform") != w.npos;
    EXPECT_TRUE(warned);
}

TEST(CpuGltf, SparseAccessorAndIntegerUvs) {
    GltfBuilder b = twoPrimitiveQuad();
    // Sparse: move vertex 2 to (2, 2, 0).
    const int idx = b.accessor(std::vector<uint16_t>{2}, 5123, "SCALAR", 1);
    const int val = b.accessor(std::vector<float>{2, 2, 0}, 5126, "VEC3", 1);
    json& pos = b.doc["accessors"][0];
    pos["sparse"] = {
        {"count", 1},
        {"indices",
         {{"bufferView", b.doc["accessors"][idx]["bufferView"]}, {"componentType", 5123}}},
        {"values", {{"bufferView", b.doc["accessors"][val]["bufferView"]}}}};
    // Normalized unsigned-byte UVs (padded to 4-byte elements by a stride).
    const int uv =
        b.accessor(std::vector<uint8_t>{0, 255, 0, 0, 255, 255, 0, 0, 255, 0, 0, 0, 0, 0, 0, 0},
                   5121, "VEC2", 4);
    b.doc["accessors"][uv]["normalized"] = true;
    b.doc["bufferViews"][b.doc["accessors"][uv]["bufferView"].get<int>()]["byteStride"] = 4;
    b.doc["meshes"][0]["primitives"][0]["attributes"]["TEXCOORD_0"] = uv;
    TempDir dir;
    const Scene s = loadGltf(b.writeGltf(dir, "sparse.gltf"));
    EXPECT_EQ(s.vertices[2].position, glm::vec3(2, 2, 0));
    EXPECT_EQ(s.vertices[0].uv, glm::vec2(0, 1));
    EXPECT_EQ(s.vertices[2].uv, glm::vec2(1, 0));
}

// ---------------------------------------------------------------------------------------------
// Bad input: every case names the file and the problem
// ---------------------------------------------------------------------------------------------

TEST(CpuSceneErrors, MissingFiles) {
    expectError([] { loadSceneFile("/nonexistent/nowhere.json"); }, {"nowhere.json", "not found"});
    expectError([] { loadGltf("/nonexistent/nowhere.gltf"); }, {"nowhere.gltf", "not found"});
    TempDir dir;
    const std::string path = dir.write("s.json", R"({"gltf": "absent.gltf"})");
    expectError([&] { loadSceneFile(path); }, {"absent.gltf", "not found"});
}

TEST(CpuSceneErrors, MalformedJsonAndGltf) {
    TempDir dir;
    const std::string json1 = dir.write("broken.json", R"({"gltf": "x.gltf",)");
    expectError([&] { loadSceneFile(json1); }, {"broken.json", "malformed JSON"});
    const std::string gltf = dir.write("broken.gltf", R"({"asset": {"version": "2.0"}, )");
    expectError([&] { loadGltf(gltf); }, {"broken.gltf", "malformed glTF"});
}

TEST(CpuSceneErrors, UnknownKeysAndBadValues) {
    TempDir dir;
    auto check = [&](const std::string& name, const std::string& text,
                     std::initializer_list<std::string> fragments) {
        const std::string path = dir.write(name, text);
        SCOPED_TRACE(name);
        expectError([&] { loadSceneFile(path); }, fragments);
    };
    const std::string box = R"("procedural": {"generator": "cornell_box"})";
    check("colour.json",
          "{" + box + R"(, "lights": [{"type": "point", "position": [0,0,0], "intensity": 1,
                                        "colour": [1,1,1]}]})",
          {"colour.json", "unknown key \"lights[0].colour\""});
    check("toplevel.json", "{" + box + R"(, "lihgts": []})", {"toplevel.json", "\"lihgts\""});
    check("proc.json", R"({"procedural": {"generator": "cornell_box", "wall": 1}})",
          {"proc.json", "procedural.wall"});
    check("cone.json",
          "{" + box + R"(, "lights": [{"type": "spot", "position": [0,0,0], "direction": [0,-1,0],
                                        "intensity": 1, "outer_cone_deg": 120}]})",
          {"cone.json", "lights[0].outer_cone_deg", "out of range"});
    check("cones.json",
          "{" + box + R"(, "lights": [{"type": "spot", "position": [0,0,0], "direction": [0,-1,0],
                         "intensity": 1, "inner_cone_deg": 40, "outer_cone_deg": 30}]})",
          {"cones.json", "outer_cone_deg must be >= inner_cone_deg"});
    check("negative.json",
          "{" + box + R"(, "lights": [{"type": "point", "position": [0,0,0], "intensity": -1}]})",
          {"negative.json", "lights[0].intensity", "out of range"});
    check("zero.json", "{" + box + R"(, "lights": [{"type": "directional", "direction": [0,0,0],
                                        "intensity": 1}]})",
          {"zero.json", "lights[0].direction", "zero-length"});
    check("type.json", "{" + box + R"(, "exposure_ev": "bright"})",
          {"type.json", "exposure_ev", "expected a number"});
    check("res.json", "{" + box + R"(, "resolution": [0, 64]})",
          {"res.json", "resolution[0]", "out of range"});
    check("bigres.json", "{" + box + R"(, "resolution": [64, 20000]})",
          {"bigres.json", "resolution[1]"});
    check("cam.json", "{" + box + R"(, "camera": {"position": [1,1,1], "target": [1,1,1]}})",
          {"cam.json", "camera", "position equals target"});
    check("both.json", R"({"gltf": "a.gltf", "procedural": {"generator": "cornell_box"}})",
          {"both.json", "exactly one"});
    check("none.json", R"({"name": "x"})", {"none.json", "exactly one"});
    check("mat.json", "{" + box + R"(, "material_overrides": {"flor": {"roughness": 0.5}}})",
          {"mat.json", "unknown material \"flor\""});
    check("albedo.json", R"({"procedural": {"generator": "cornell_box", "albedo_scale": -1}})",
          {"albedo.json", "procedural.albedo_scale"});
    check("variantkey.json", "{" + box + R"(, "variants": {"v": {"lihgts": []}}})",
          {"variantkey.json", "variant \"v\"", "\"lihgts\""});
    check("far.json", "{" + box + R"(, "translate": [0, 2e7, 0]})",
          {"far.json", "translate", "out of range"});
    check("translate2.json", "{" + box + R"(, "translate": [0, 1]})",
          {"translate2.json", "translate"});
}

// `translate` moves geometry, point/spot lights and the camera after `scale`; directions and
// directional lights stay (docs/scenes.md)
TEST(CpuSceneDescription, TranslateMovesEveryPositionAfterScale) {
    TempDir dir;
    const std::string path = dir.write("moved.json", R"({
        "procedural": {"generator": "cornell_box"},
        "extra_lights": [{"type": "point", "position": [0.1, 0.2, 0.3], "intensity": 1},
                         {"type": "directional", "direction": [0, -1, 0], "intensity": 1}],
        "variants": {"moved": {"scale": 2, "translate": [5000, -10, 3000]}}})");
    const Scene a = loadSceneFile(path);
    const Scene b = loadSceneFile(path, "moved");
    ASSERT_EQ(a.vertices.size(), b.vertices.size());
    const glm::vec3 t(5000.0f, -10.0f, 3000.0f);
    for (size_t i = 0; i < a.vertices.size(); i += 7)
        EXPECT_EQ(b.vertices[i].position,
                  glm::vec3(glm::dvec3(2.0f * a.vertices[i].position) + glm::dvec3(t)));
    EXPECT_EQ(b.vertices[0].normal, a.vertices[0].normal);
    const Light& point = b.lights[b.lights.size() - 2];
    EXPECT_NEAR(point.position.x, 5000.2f, 1e-3f);
    EXPECT_NEAR(point.position.z, 3000.6f, 1e-3f);
    EXPECT_EQ(b.lights.back().direction, a.lights.back().direction);
    EXPECT_NEAR(b.camera.position.x, 2.0f * a.camera.position.x + 5000.0f, 1e-3f);
    EXPECT_NEAR(b.camera.target.y, 2.0f * a.camera.target.y - 10.0f, 1e-3f);
    EXPECT_NEAR(b.caps.bounds.lo.x, 2.0f * a.caps.bounds.lo.x + 5000.0f, 1e-3f);
}

TEST(CpuSceneErrors, TranslateRefusesAnAnimatedScene) {
    TempDir dir;
    const std::string path = dir.write("anim.json", R"({
        "procedural": {"generator": "cornell_box"}, "translate": [1, 0, 0],
        "animation": {"frames": 2, "tracks": []}})");
    expectError([&] { loadSceneFile(path); }, {"anim.json", "translate", "animated"});
}

// A triangle's mean emission over its uv footprint (core/scene/emission.h): exact for a
// texture that is linear in u (a ramp, clamped), and each half of a quad gets its own mean
TEST(CpuSceneEmission, TriangleMeanIsTheTexturesMeanOverItsUvFootprint) {
    Scene s;
    Texture ramp;
    ramp.width = 256;
    ramp.height = 1;
    ramp.colorSpace = ColorSpace::Linear;
    ramp.wrapU = ramp.wrapV = WrapMode::ClampToEdge;
    for (int i = 0; i < 256; ++i)
        ramp.rgba.insert(ramp.rgba.end(), {uint8_t(i), uint8_t(i), uint8_t(i), 255});
    s.textures.push_back(ramp);
    Material m;
    m.emissiveFactor = glm::vec3(2.0f);
    m.emissiveTexture = 0;
    s.materials.push_back(m);
    // uv (0.25, 0) (0.75, 0) (0.75, 1): the mean u is 7/12; value(u) = (256 u - 0.5) / 255
    appendQuad(s, {0, 0, 0}, {1, 0, 0}, {1, 0, 1}, {0, 0, 1}, {0, 1, 0}, 0);
    for (Vertex& v : s.vertices)
        v.uv.x = 0.25f + 0.5f * v.uv.x;
    for (size_t t = 0; t < 2; ++t) {
        glm::vec2 meanUv(0.0f);
        for (int k = 0; k < 3; ++k)
            meanUv += s.vertices[s.indices[3 * t + size_t(k)]].uv / 3.0f;
        const float expected = 2.0f * (256.0f * meanUv.x - 0.5f) / 255.0f;
        EXPECT_NEAR(meanTriangleEmission(s, t).x, expected, 2e-4f) << "triangle " << t;
    }
    EXPECT_GT(std::abs(meanTriangleEmission(s, 0).x - meanTriangleEmission(s, 1).x), 0.3f);
    // No texture: the factor
    s.materials[0].emissiveTexture = -1;
    EXPECT_EQ(meanTriangleEmission(s, 0), glm::vec3(2.0f));
}

TEST(CpuSceneErrors, UnknownVariantListsTheAvailableOnes) {
    expectError([] { loadSceneFile(kScenes + "/cornell_box.json#nope"); },
                {"cornell_box.json", "unknown variant \"nope\"", "point, spot"});
}

TEST(CpuSceneErrors, TwoRoomsBadParametersNameTheKey) {
    TempDir dir;
    auto check = [&](const std::string& name, const std::string& procedural,
                     std::initializer_list<std::string> fragments) {
        const std::string path =
            dir.write(name, R"({"procedural": {"generator": "two_rooms", )" + procedural + "}}");
        SCOPED_TRACE(name);
        expectError([&] { loadSceneFile(path); }, fragments);
    };
    check("size.json", R"("room_size": [0.5, -0.5, 0.5])",
          {"size.json", "procedural.room_size[1]", "out of range"});
    check("size3.json", R"("room_size": [0.5, 0.5])", {"size3.json", "procedural.room_size"});
    check("thick.json", R"("wall_thickness": -0.01)",
          {"thick.json", "procedural.wall_thickness", "out of range"});
    check("thin.json", R"("wall_thickness": 0)", {"thin.json", "procedural.wall_thickness"});
    check("order.json", R"("door": [0.6, 0.0, 0.4, 0.5])",
          {"order.json", "procedural.door", "z0 < z1"});
    check("outside.json", R"("door": [0.2, 0.0, 1.2, 0.5])",
          {"outside.json", "procedural.door[2]", "out of range"});
    check("short.json", R"("door": [0.2, 0.0, 0.5])", {"short.json", "procedural.door"});
    check("flag.json", R"("door_open": "no")", {"flag.json", "procedural.door_open"});
    check("red.json", R"("red": [1.5, 0, 0])", {"red.json", "procedural.red"});
    check("key.json", R"("doors": [0.2, 0.0, 0.5, 0.5])", {"key.json", "procedural.doors"});
    const std::string path = dir.write("gen.json", R"({"procedural": {"generator": "two_room"}})");
    expectError([&] { loadSceneFile(path); },
                {"gen.json", "unknown generator \"two_room\"", "cornell_box, two_rooms"});
}

TEST(CpuSceneErrors, NanVertex) {
    GltfBuilder b;
    const float nan = std::nanf("");
    b.mesh(b.positions({0, 0, 0, 1, nan, 0, 0, 1, 0}));
    TempDir dir;
    const std::string path = b.writeGltf(dir, "nan.gltf");
    expectError([&] { loadGltf(path); }, {"nan.gltf", "testMesh", "1 of 3 POSITION", "NaN"});
}

TEST(CpuSceneErrors, IndexOutOfRange) {
    GltfBuilder b;
    b.mesh(b.positions({0, 0, 0, 1, 0, 0, 0, 1, 0}), b.indices({0, 1, 7}));
    TempDir dir;
    const std::string path = b.writeGltf(dir, "index.gltf");
    expectError([&] { loadGltf(path); }, {"index.gltf", "testMesh", "out of range"});
}

TEST(CpuSceneErrors, MissingTexture) {
    GltfBuilder b = twoPrimitiveQuad();
    b.doc["meshes"][0]["primitives"][0]["material"] = 0;
    b.doc["materials"] = {
        {{"name", "m"}, {"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 0}}}}}}};
    b.doc["textures"] = {{{"source", 0}}};
    b.doc["images"] = {{{"uri", "missing.png"}}};
    TempDir dir;
    const std::string path = b.writeGltf(dir, "tex.gltf");
    expectError([&] { loadGltf(path); }, {"tex.gltf", "missing.png", "missing"});
}

TEST(CpuSceneErrors, UnsupportedRequiredExtension) {
    GltfBuilder b = twoPrimitiveQuad();
    b.doc["extensionsUsed"] = {"KHR_draco_mesh_compression"};
    b.doc["extensionsRequired"] = {"KHR_draco_mesh_compression"};
    TempDir dir;
    const std::string path = b.writeGltf(dir, "draco.gltf");
    expectError([&] { loadGltf(path); },
                {"draco.gltf", "unsupported", "KHR_draco_mesh_compression"});
}

TEST(CpuSceneErrors, DegenerateTrianglesAreDroppedAndCounted) {
    GltfBuilder b;
    const int pos = b.positions({0, 0, 0, 1, 0, 0, 0, 1, 0, 2, 0, 0});
    // One good triangle, one with a repeated index, one collinear (zero area).
    b.mesh(pos, b.indices({0, 1, 2, 0, 0, 2, 0, 1, 3}));
    TempDir dir;
    const Scene s = loadGltf(b.writeGltf(dir, "degenerate.gltf"));
    EXPECT_EQ(s.triangleCount(), 1u);
    bool counted = false;
    for (const auto& w : s.warnings) {
        counted |= w.find("degenerate.gltf") != w.npos && w.find("dropped 2 degenerate") != w.npos;
    }
    EXPECT_TRUE(counted);
}

TEST(CpuSceneErrors, ZeroNormalsAreRecomputed) {
    GltfBuilder b = twoPrimitiveQuad();
    const int n =
        b.accessor(std::vector<float>{0, 0, 1, 0, 0, 0, 0, 0, 1, 0, 0, 1}, 5126, "VEC3", 4);
    b.doc["meshes"][0]["primitives"][0]["attributes"]["NORMAL"] = n;
    TempDir dir;
    const Scene s = loadGltf(b.writeGltf(dir, "normals.gltf"));
    EXPECT_EQ(s.vertices[1].normal, glm::vec3(0, 0, 1));
    bool warned = false;
    for (const auto& w : s.warnings)
        warned |= w.find("recomputed 1 zero-length") != w.npos;
    EXPECT_TRUE(warned);
}

}  // namespace
