// Vulkan backend tests (Gpu* suites): run on lavapipe or any Vulkan 1.3 device with validation
// on; every test fails on any validation error or warning.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <memory>

#include <glm/gtc/packing.hpp>

#include "core/gpu/gpu_scene.h"
#include "core/util/error.h"
#include "core/vk/barrier.h"
#include "core/vk/buffer.h"
#include "core/vk/context.h"
#include "core/vk/descriptors.h"
#include "core/vk/image.h"
#include "core/vk/pipeline.h"
#include "core/vk/rendering.h"
#include "core/vk/shader.h"
#include "core/vk/timer.h"

using namespace gilab;
using namespace gilab::vk;

namespace {

Context& sharedContext() {
    static std::unique_ptr<Context> ctx = [] {
        ContextOptions options;
        options.validation = true;
        options.syncValidation = true;  // cheap at test sizes; catches missing barriers
        return std::make_unique<Context>(options);
    }();
    return *ctx;
}

class GpuFixture : public ::testing::Test {
protected:
    Context& ctx() { return sharedContext(); }
    void SetUp() override { ctx().clearValidationMessages(); }
    void TearDown() override {
        EXPECT_EQ(ctx().validationErrorCount(), 0u);
        EXPECT_EQ(ctx().validationWarningCount(), 0u);
        if (ctx().validationErrorCount() + ctx().validationWarningCount() > 0) {
            for (const auto& m : ctx().validationMessages())
                ADD_FAILURE() << m;
        }
        ctx().clearValidationMessages();
    }
};

class GpuContext : public GpuFixture {};
class GpuBuffer : public GpuFixture {};
class GpuMemory : public GpuFixture {};
class GpuCompute : public GpuFixture {};
class GpuImage : public GpuFixture {};
class GpuGraphics : public GpuFixture {};
class GpuTimerTest : public GpuFixture {};
class GpuSceneTest : public GpuFixture {};
class GpuShader : public GpuFixture {};

float srgbToLinear(float c) {
    return c <= 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f);
}

}  // namespace

TEST_F(GpuContext, ChoosesADeviceAndExplainsCandidates) {
    EXPECT_TRUE(ctx().validationEnabled());
    EXPECT_NE(ctx().device(), VK_NULL_HANDLE);
    EXPECT_FALSE(ctx().deviceName().empty());
    EXPECT_EQ(ctx().apiVersion().rfind("1.", 0), 0u);
    ASSERT_FALSE(ctx().candidates().empty());
    int chosen = 0;
    for (const auto& c : ctx().candidates()) {
        EXPECT_FALSE(c.reason.empty()) << c.name;
        EXPECT_FALSE(c.type.empty()) << c.name;
        chosen += c.chosen ? 1 : 0;
        if (c.chosen) {
            EXPECT_EQ(c.name, ctx().deviceName());
        }
    }
    EXPECT_EQ(chosen, 1);
    std::printf("device: %s (%s), driver %s %s, API %s, float atomics %d, timestamps %d\n",
                ctx().deviceName().c_str(), ctx().deviceType().c_str(), ctx().driverName().c_str(),
                ctx().driverInfo().c_str(), ctx().apiVersion().c_str(),
                int(ctx().hasFloatAtomics()), int(ctx().timestampsSupported()));
}

TEST_F(GpuContext, BadDeviceFilterThrowsWithCandidateList) {
    const char* env = std::getenv("GILAB_DEVICE");
    std::string saved = env ? env : "";
    unsetenv("GILAB_DEVICE");
    ContextOptions options;
    options.deviceFilter = "no-such-device-xyz";
    try {
        Context bad(options);
        ADD_FAILURE() << "expected an exception";
    } catch (const Error& e) {
        std::string message = e.what();
        EXPECT_NE(message.find("no-such-device-xyz"), std::string::npos) << message;
        EXPECT_NE(message.find(ctx().deviceName()), std::string::npos) << message;
    }
    if (env) setenv("GILAB_DEVICE", saved.c_str(), 1);
}

TEST_F(GpuBuffer, MappedAndDeviceLocalRoundTrip) {
    std::vector<uint32_t> data(1000);
    for (size_t i = 0; i < data.size(); ++i)
        data[i] = uint32_t(i * 7 + 3);
    for (MemoryUsage usage :
         {MemoryUsage::Upload, MemoryUsage::Readback, MemoryUsage::DeviceLocal}) {
        Buffer buffer(ctx(), data.size() * 4, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, usage,
                      "test/roundtrip");
        EXPECT_EQ(buffer.mapped() == nullptr, usage == MemoryUsage::DeviceLocal);
        buffer.uploadVector(data);
        EXPECT_EQ(buffer.downloadVector<uint32_t>(data.size()), data);
        uint32_t patch[2] = {11, 22};
        buffer.upload(patch, sizeof(patch), 40);
        uint32_t back[3];
        buffer.download(back, sizeof(back), 36);
        EXPECT_EQ(back[0], data[9]);
        EXPECT_EQ(back[1], 11u);
        EXPECT_EQ(back[2], 22u);
    }
    Buffer empty(ctx(), 0, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, MemoryUsage::DeviceLocal,
                 "test/empty");
    EXPECT_GE(empty.size(), 16u);
    Buffer small(ctx(), 16, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, MemoryUsage::Upload, "test/s");
    EXPECT_THROW(small.upload(data.data(), 32), Error);
}

TEST_F(GpuMemory, TrackerCountsUpAndBackToZero) {
    MemoryTracker& memory = ctx().memory();
    VkDeviceSize before = memory.total();
    EXPECT_EQ(memory.totalWithPrefix("test/"), 0u);
    memory.resetPeak();
    {
        Buffer a(ctx(), 4096, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, MemoryUsage::DeviceLocal,
                 "test/a");
        ImageDesc desc;
        desc.width = desc.height = 16;
        desc.usage = VK_IMAGE_USAGE_STORAGE_BIT;
        desc.name = "test/image";
        Image image(ctx(), desc);
        auto tags = memory.byTag();
        ASSERT_TRUE(tags.count("test/a"));
        ASSERT_TRUE(tags.count("test/image"));
        EXPECT_GE(tags["test/a"], 4096u);
        EXPECT_GE(tags["test/image"], 16u * 16u * 16u);
        EXPECT_EQ(memory.totalWithPrefix("test/"), tags["test/a"] + tags["test/image"]);
        EXPECT_EQ(memory.total(), before + memory.totalWithPrefix("test/"));
        Buffer moved = std::move(a);  // moves do not double count
        EXPECT_EQ(memory.byTag()["test/a"], tags["test/a"]);
    }
    EXPECT_EQ(memory.totalWithPrefix("test/"), 0u);
    EXPECT_EQ(memory.total(), before);
    EXPECT_GE(memory.peak(), before + 4096u);
    memory.add("x/y", 10);
    memory.remove("x/y", 10);
    EXPECT_EQ(memory.byTag().count("x/y"), 0u);
}

namespace {
struct FillPush {
    uint32_t width, height, seed;
};

/** The test_fill pipeline with its set: image at binding 0, buffer at binding 1. */
struct FillPass {
    FillPass(Context& ctx, Image& image, Buffer& buffer)
        : layout(ctx,
                 {{0, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE}, {1, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER}},
                 "test/fillLayout"),
          set(ctx, layout, 0, "test/fillSet"),
          pipelineLayout(ctx, {layout.handle()}, sizeof(FillPush), VK_SHADER_STAGE_COMPUTE_BIT,
                         "test/fill"),
          pipeline(ctx, "common/test_fill.comp", pipelineLayout) {
        set.writeStorageImage(0, image.view());
        set.writeBuffer(1, buffer);
    }
    void record(VkCommandBuffer cmd, uint32_t w, uint32_t h, uint32_t seed) {
        pipeline.bind(cmd);
        VkDescriptorSet s = set.handle();
        vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, pipelineLayout.handle(), 0, 1,
                                &s, 0, nullptr);
        pipelineLayout.push(cmd, FillPush{w, h, seed});
        dispatch2D(cmd, w, h);
    }
    DescriptorSetLayout layout;
    DescriptorSet set;
    PipelineLayout pipelineLayout;
    ComputePipeline pipeline;
};
}  // namespace

TEST_F(GpuCompute, FillWritesKnownPattern) {
    const uint32_t w = 37, h = 21;  // not multiples of the 8x8 group
    ImageDesc desc;
    desc.width = w;
    desc.height = h;
    desc.usage = VK_IMAGE_USAGE_STORAGE_BIT;
    desc.name = "test/fillImage";
    Image image(ctx(), desc);
    Buffer buffer(ctx(), w * h * 4, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, MemoryUsage::DeviceLocal,
                  "test/fillBuffer");
    FillPass pass(ctx(), image, buffer);
    ctx().submitAndWait([&](VkCommandBuffer cmd) {
        image.transition(cmd, VK_IMAGE_LAYOUT_GENERAL);
        pass.record(cmd, w, h, 5);
    });
    uint32_t channels = 0;
    std::vector<float> texels = image.readbackFloat(ctx(), 0, 0, &channels);
    std::vector<uint32_t> values = buffer.downloadVector<uint32_t>(w * h);
    ASSERT_EQ(channels, 4u);
    ASSERT_EQ(texels.size(), size_t(w) * h * 4);
    EXPECT_EQ(image.layout(), VK_IMAGE_LAYOUT_GENERAL);  // readback restores the layout
    int bad = 0;
    for (uint32_t y = 0; y < h; ++y) {
        for (uint32_t x = 0; x < w; ++x) {
            const float* t = &texels[(y * w + x) * 4];
            bool ok = t[0] == float(x) && t[1] == float(y) && t[2] == float(x * y) &&
                      t[3] == 0.5f && values[y * w + x] == x * 1000 + y + 5;
            bad += ok ? 0 : 1;
        }
    }
    EXPECT_EQ(bad, 0);
}

TEST_F(GpuImage, ReadbackFloatConvertsFormats) {
    const uint32_t w = 4, h = 3;
    std::vector<float> values(w * h * 4);
    for (size_t i = 0; i < values.size(); ++i)
        values[i] = float(i) * 0.25f - 3.0f;
    {
        ImageDesc desc{ImageKind::Image2D, VK_FORMAT_R32G32B32A32_SFLOAT, w, h};
        desc.name = "test/rgba32f";
        Image image(ctx(), desc);
        image.upload(ctx(), values.data(), values.size() * 4);
        EXPECT_EQ(image.layout(), VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL);
        EXPECT_EQ(image.readbackFloat(ctx()), values);
        EXPECT_EQ(image.layout(), VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL);
    }
    {
        std::vector<uint16_t> half(values.size());
        for (size_t i = 0; i < values.size(); ++i)
            half[i] = glm::packHalf1x16(values[i]);
        ImageDesc desc{ImageKind::Image2D, VK_FORMAT_R16G16B16A16_SFLOAT, w, h};
        desc.name = "test/rgba16f";
        Image image(ctx(), desc);
        image.upload(ctx(), half.data(), half.size() * 2);
        EXPECT_EQ(image.readbackFloat(ctx()), values);  // quarter steps are exact in fp16
    }
    {
        std::vector<uint8_t> bytes(w * h * 4);
        for (size_t i = 0; i < bytes.size(); ++i)
            bytes[i] = uint8_t(i * 21);
        ImageDesc desc{ImageKind::Image2D, VK_FORMAT_R8G8B8A8_SRGB, w, h};
        desc.name = "test/srgb";
        Image image(ctx(), desc);
        image.upload(ctx(), bytes.data(), bytes.size());
        EXPECT_EQ(image.readback(ctx()), bytes);
        std::vector<float> f = image.readbackFloat(ctx());
        ASSERT_EQ(f.size(), bytes.size());
        for (size_t i = 0; i < f.size(); ++i) {
            float v = bytes[i] / 255.0f;
            EXPECT_NEAR(f[i], i % 4 == 3 ? v : srgbToLinear(v), 1e-6f) << i;
        }
    }
    {
        ImageDesc desc{ImageKind::Image2D, VK_FORMAT_R32G32B32A32_SFLOAT, 8, 8};
        desc.mipLevels = 0;  // full chain
        desc.name = "test/mips";
        Image image(ctx(), desc);
        EXPECT_EQ(image.desc().mipLevels, 4u);
        std::vector<float> ones(8 * 8 * 4, 2.0f);
        image.upload(ctx(), ones.data(), ones.size() * 4);
        image.generateMips(ctx());
        EXPECT_EQ(image.readbackFloat(ctx(), 0, 3), std::vector<float>(4, 2.0f));
    }
}

TEST_F(GpuGraphics, TriangleViaDynamicRendering) {
    const uint32_t w = 32, h = 32;
    ImageDesc desc{ImageKind::Image2D, VK_FORMAT_R32G32B32A32_SFLOAT, w, h};
    desc.usage = VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT;
    desc.name = "test/target";
    Image target(ctx(), desc);
    PipelineLayout layout(ctx(), {}, 16, VK_SHADER_STAGE_FRAGMENT_BIT, "test/triangle");
    GraphicsPipelineDesc p;
    p.vertexShader = "common/test_triangle.vert";
    p.fragmentShader = "common/test_triangle.frag";
    p.sceneVertexInput = false;
    p.colorFormats = {VK_FORMAT_R32G32B32A32_SFLOAT};
    p.name = "test/triangle";
    GraphicsPipeline pipeline(ctx(), p, layout);
    const float color[4] = {0.9f, 0.6f, 0.3f, 1.0f};
    ctx().submitAndWait([&](VkCommandBuffer cmd) {
        target.transition(cmd, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL);
        {
            RenderingScope scope(cmd, target.extent2D(),
                                 {{target.view(), VkClearColorValue{{0.1f, 0.2f, 0.3f, 1.0f}}}});
            pipeline.bind(cmd);
            layout.push(cmd, color, sizeof(color));
            vkCmdDraw(cmd, 3, 1, 0, 0);
        }
        target.transition(cmd, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL);
    });
    std::vector<float> pixels = target.readbackFloat(ctx());
    auto at = [&](uint32_t x, uint32_t y, int c) { return pixels[(y * w + x) * 4 + c]; };
    for (int c = 0; c < 4; ++c) {
        EXPECT_EQ(at(16, 16, c), color[c]) << c;  // inside
        EXPECT_EQ(at(1, 1, c), (std::array<float, 4>{0.1f, 0.2f, 0.3f, 1.0f}[c])) << c;
        EXPECT_EQ(at(30, 30, c), (std::array<float, 4>{0.1f, 0.2f, 0.3f, 1.0f}[c])) << c;
    }
}

TEST_F(GpuTimerTest, TwoNamedPassesHaveFiniteTimes) {
    const uint32_t w = 64, h = 64;
    ImageDesc desc;
    desc.width = w;
    desc.height = h;
    desc.usage = VK_IMAGE_USAGE_STORAGE_BIT;
    desc.name = "test/timerImage";
    Image image(ctx(), desc);
    Buffer buffer(ctx(), w * h * 4, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, MemoryUsage::DeviceLocal,
                  "test/timerBuffer");
    FillPass pass(ctx(), image, buffer);
    GpuTimer timer(ctx());
    for (int frame = 0; frame < 2; ++frame) {
        ctx().submitAndWait([&](VkCommandBuffer cmd) {
            timer.reset(cmd);
            image.transition(cmd, VK_IMAGE_LAYOUT_GENERAL);
            {
                ScopedGpuPass p(timer, cmd, "alpha");
                pass.record(cmd, w, h, 1);
            }
            memoryBarrier(cmd);
            {
                ScopedGpuPass p(timer, cmd, "beta");
                pass.record(cmd, w, h, 2);
            }
            memoryBarrier(cmd);
            {
                ScopedGpuPass p(timer, cmd, "alpha");  // same name again: summed
                pass.record(cmd, w, h, 3);
            }
        });
        std::vector<PassTime> times = timer.resolve();
        ASSERT_EQ(times.size(), 2u);
        EXPECT_EQ(times[0].name, "alpha");
        EXPECT_EQ(times[1].name, "beta");
        for (const auto& t : times) {
            if (ctx().timestampsSupported()) {
                EXPECT_TRUE(std::isfinite(t.gpuMs)) << t.name;
                EXPECT_GE(t.gpuMs, 0.0) << t.name;
            } else {
                EXPECT_TRUE(std::isnan(t.gpuMs));
            }
            EXPECT_GE(t.cpuRecordMs, 0.0);
        }
    }
}

TEST_F(GpuShader, MissingShaderThrowsWithName) {
    try {
        findShader("common/no_such_shader.comp");
        ADD_FAILURE() << "expected an exception";
    } catch (const Error& e) {
        std::string message = e.what();
        EXPECT_NE(message.find("common/no_such_shader.comp"), std::string::npos);
        EXPECT_NE(message.find("common/test_fill.comp"), std::string::npos);  // lists known
    }
    EXPECT_THROW(ComputePipeline(ctx(), "common/no_such_shader.comp", PipelineLayout(ctx(), {})),
                 Error);
    auto names = registeredShaders();
    EXPECT_NE(std::find(names.begin(), names.end(), "common/test_scene.comp"), names.end());
}

namespace {

/** A unit quad in z = 0 as two triangles: 0 textured (sRGB 2x2, wrap U repeat, V clamp, alpha
 *  mask), 1 untextured, glossy and emissive. One spot light. */
Scene makeTestScene() {
    Scene s;
    s.name = "test_quad";
    glm::vec3 n(0.0f, 0.0f, 1.0f);
    s.vertices = {{{0, 0, 0}, n, {0, 0}},
                  {{1, 0, 0}, n, {1, 0}},
                  {{1, 1, 0}, n, {1, 1}},
                  {{0, 1, 0}, n, {0, 1}}};
    s.indices = {0, 1, 2, 0, 2, 3};
    s.triangleMaterials = {0, 1};
    Texture t;
    t.name = "test_texture";
    t.width = t.height = 2;
    t.rgba = {255, 0, 0, 255, 0, 255, 0, 255, 0, 0, 255, 255, 128, 128, 128, 100};
    t.colorSpace = ColorSpace::Srgb;
    t.wrapU = WrapMode::Repeat;
    t.wrapV = WrapMode::ClampToEdge;
    s.textures.push_back(t);
    Material textured;
    textured.name = "textured";
    textured.baseColorFactor = {0.5f, 1.0f, 1.0f, 1.0f};
    textured.baseColorTexture = 0;
    textured.alphaMode = AlphaMode::Mask;
    textured.alphaCutoff = 0.5f;
    Material plain;
    plain.name = "plain";
    plain.baseColorFactor = {0.2f, 0.4f, 0.6f, 1.0f};
    plain.metallic = 0.3f;
    plain.roughness = 0.7f;
    plain.emissiveFactor = {1.0f, 2.0f, 3.0f};
    s.materials = {textured, plain};
    Light spot;
    spot.type = LightType::Spot;
    spot.position = {0.0f, 2.0f, 0.0f};
    s.lights.push_back(spot);
    return s;
}

struct Query {
    uint32_t triangle;
    float u, v, lod;
};

}  // namespace

TEST_F(GpuSceneTest, PackTexturesBuildsMipChain) {
    Scene s = makeTestScene();
    PackedTextures packed = packTextures(s.textures);
    ASSERT_EQ(packed.meta.size(), 3u);
    EXPECT_EQ(packed.meta[0], glm::uvec4(1, 2, 1, kWrapRepeat | (kWrapClampToEdge << 4)));
    EXPECT_EQ(packed.meta[1], glm::uvec4(0, 2, 2, 0));
    EXPECT_EQ(packed.meta[2], glm::uvec4(4, 1, 1, 0));
    ASSERT_EQ(packed.texels.size(), 5u);
    EXPECT_EQ(packed.texels[0], 0xff0000ffu);  // red, R in the low byte
}

TEST_F(GpuSceneTest, ShaderReadsSceneThroughSceneGlsl) {
    Scene s = makeTestScene();
    GpuScene gpu(ctx(), s);
    EXPECT_EQ(gpu.indexCount(), 6u);
    EXPECT_EQ(gpu.lightCount(), 1u);
    EXPECT_EQ(gpu.emissiveTriangleCount(), 1u);
    EXPECT_GT(ctx().memory().totalWithPrefix("scene/"), 0u);
    gpu.setLightShadowIndex(0, 3);
    EXPECT_EQ(gpu.lights().downloadVector<GpuLight>(1)[0].cone.z, 3.0f);

    std::vector<Query> base = {
        {0, 0.25f, 0.25f, 0.0f},  // texel (0,0): red
        {1, 0.25f, 0.25f, 0.0f},  // untextured material
        {0, 1.25f, 0.25f, 0.0f},  // U repeats
        {0, 0.25f, -3.0f, 0.0f},  // V clamps
        {0, 0.5f, 0.25f, 0.0f},   // half red, half green (linear)
        {0, 0.75f, 0.75f, 0.0f},  // texel (1,1): grey, alpha 100/255 -> cut out
        {0, 0.25f, 0.25f, 1.0f},  // mip 1 (1x1 average)
    };
    std::vector<Query> queries;
    for (int r = 0; r < 10; ++r)
        queries.insert(queries.end(), base.begin(), base.end());
    Buffer queryBuffer(ctx(), queries.size() * sizeof(Query), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT,
                       MemoryUsage::Upload, "test/queries");
    queryBuffer.uploadVector(queries);
    Buffer results(ctx(), queries.size() * 6 * 16, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT,
                   MemoryUsage::DeviceLocal, "test/results");
    DescriptorSetLayout ioLayout(
        ctx(), {{0, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER}, {1, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER}},
        "test/io");
    DescriptorSet io(ctx(), ioLayout, 0, "test/io");
    io.writeBuffer(0, queryBuffer);
    io.writeBuffer(1, results);
    PipelineLayout layout(ctx(), {gpu.layout().handle(), ioLayout.handle()}, 0, VK_SHADER_STAGE_ALL,
                          "test/scene");
    ComputePipeline pipeline(ctx(), "common/test_scene.comp", layout);
    ctx().submitAndWait([&](VkCommandBuffer cmd) {
        pipeline.bind(cmd);
        VkDescriptorSet sets[2] = {gpu.set().handle(), io.handle()};
        vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, layout.handle(), 0, 2, sets, 0,
                                nullptr);
        dispatch1D(cmd, uint32_t(queries.size()), 64);
    });
    std::vector<glm::vec4> out = results.downloadVector<glm::vec4>(queries.size() * 6);

    const float red = 1.0f, grey = srgbToLinear(128.0f / 255.0f);
    auto expectVec = [](glm::vec4 got, glm::vec4 want, float tol, const std::string& what) {
        for (int c = 0; c < 4; ++c)
            EXPECT_NEAR(got[c], want[c], tol) << what << " [" << c << "]";
    };
    for (size_t r = 0; r < 10; ++r) {
        const glm::vec4* q = &out[r * base.size() * 6];
        auto at = [&](size_t query, size_t slot) { return q[query * 6 + slot]; };
        std::string tag = " (repeat " + std::to_string(r) + ")";
        expectVec(at(0, 0), {0.5f, 1, 1, 1}, 0, "factor" + tag);
        expectVec(at(0, 1), {0.5f * red, 0, 0, 1}, 1e-5f, "texel (0,0)" + tag);
        expectVec(at(0, 3), {0, 1, 0, 1}, 1e-6f, "metal/rough, cutout, lights" + tag);
        expectVec(at(0, 4), {0.5f, 0.25f, 0, 0.5f}, 1e-6f, "interpolated position, u" + tag);
        expectVec(at(0, 5), {0, 0, 1, 2}, 1e-6f, "normal, triangle count" + tag);
        expectVec(at(1, 1), {0.2f, 0.4f, 0.6f, 1}, 1e-6f, "untextured" + tag);
        expectVec(at(1, 2), {1, 2, 3, float(kMaterialGlossy | kMaterialEmissive)}, 0,
                  "emission, flags" + tag);
        expectVec(at(1, 3), {0.3f, 0.7f, 0, 1}, 1e-6f, "metal/rough" + tag);
        expectVec(at(2, 1), at(0, 1), 1e-5f, "repeat U" + tag);
        expectVec(at(3, 1), at(0, 1), 1e-5f, "clamp V" + tag);
        expectVec(at(4, 1), {0.25f, 0.5f, 0, 1}, 1e-5f, "bilinear" + tag);
        expectVec(at(5, 1), {0.5f * grey, grey, grey, 100.0f / 255.0f}, 1e-5f, "grey" + tag);
        EXPECT_EQ(at(5, 3).z, 1.0f) << "alpha cutout" << tag;
        float mipR = (1.0f + grey) / 4.0f, mipG = (1.0f + grey) / 4.0f;
        expectVec(at(6, 1), {0.5f * mipR, mipG, mipG, (3.0f + 100.0f / 255.0f) / 4.0f}, 0.01f,
                  "mip 1" + tag);
    }
}

TEST_F(GpuSceneTest, RasterWithImplicitLodAndEmptyArrays) {
    // Same quad without lights: the lights buffer still binds (16 bytes) and length() is 0.
    Scene s = makeTestScene();
    s.lights.clear();
    GpuScene gpu(ctx(), s);
    EXPECT_EQ(gpu.lightCount(), 0u);
    const uint32_t w = 34, h = 34;  // pixel 8 has its centre at uv 0.25, pixel 25 at 0.75
    ImageDesc desc{ImageKind::Image2D, VK_FORMAT_R32G32B32A32_SFLOAT, w, h};
    desc.usage = VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT;
    desc.name = "test/sceneTarget";
    Image target(ctx(), desc);
    PipelineLayout layout(ctx(), {gpu.layout().handle()}, 0, VK_SHADER_STAGE_ALL, "test/raster");
    GraphicsPipelineDesc p;
    p.vertexShader = "common/test_scene_raster.vert";
    p.fragmentShader = "common/test_scene_raster.frag";
    p.sceneVertexInput = false;
    p.colorFormats = {desc.format};
    p.name = "test/sceneRaster";
    GraphicsPipeline pipeline(ctx(), p, layout);
    ctx().submitAndWait([&](VkCommandBuffer cmd) {
        target.transition(cmd, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL);
        RenderingScope scope(cmd, target.extent2D(),
                             {{target.view(), VkClearColorValue{{0.0f, 0.0f, 0.0f, 0.0f}}}});
        pipeline.bind(cmd);
        VkDescriptorSet set = gpu.set().handle();
        vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, layout.handle(), 0, 1, &set,
                                0, nullptr);
        vkCmdDraw(cmd, gpu.indexCount(), 1, 0, 0);
    });
    std::vector<float> pixels = target.readbackFloat(ctx());
    auto at = [&](uint32_t x, uint32_t y) {
        const float* q = &pixels[(y * w + x) * 4];
        return glm::vec4(q[0], q[1], q[2], q[3]);
    };
    glm::vec4 green = at(25, 8);  // uv (0.75, 0.25): triangle 0, texel (1, 0)
    glm::vec4 plain = at(8, 25);  // uv (0.25, 0.75): triangle 1
    for (int c = 0; c < 4; ++c) {
        EXPECT_NEAR(green[c], glm::vec4(0, 1, 0, 1)[c], 1e-3f) << c;
        EXPECT_NEAR(plain[c], glm::vec4(1.2f, 2.4f, 3.6f, 1.0f)[c], 1e-5f) << c;
    }
}
