// The path tracer's direct and emission layers against the rasteriser's `direct` technique
// (shared passes on lavapipe, validation on) on the Cornell box: this agreement is what makes
// every later GI error measured against the reference mean something. docs/reference.md has
// the exclusion rule and the measured numbers.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "tests/gpu_test_fixture.h"

#include "core/image/color.h"
#include "core/scene/mesh_builder.h"
#include "core/scene/scene_loader.h"
#include "core/technique/frame_harness.h"
#include "core/technique/registry.h"
#include "core/util/error.h"
#include "core/vk/context.h"
#include "experiments/cli/leak_causes.h"
#include "experiments/cli/light_placements.h"
#include "experiments/metrics/direct_accuracy.h"
#include "reference/path_tracer.h"

namespace gilab {
namespace {

using GpuReferenceVsDirect = test::ValidatedGpuTest;

const Image& layer(const std::vector<ImageLayer>& layers, const std::string& name) {
    for (const ImageLayer& l : layers)
        if (l.name == name) return l.image;
    throw Error("no layer " + name);
}

/** The direct technique's layers at `factor` x the scene's resolution (GPU centre samples). */
std::vector<ImageLayer> renderDirect(vk::Context& ctx, Scene scene, bool shadows, int factor) {
    scene.settings.width *= factor;
    scene.settings.height *= factor;
    ParamSet shared = defaultSharedParams();
    shared.set("shadows", shadows ? "true" : "false");
    FrameHarness h(ctx, scene, "direct", TechniqueRegistry::instance().defaultParams("direct"),
                   shared);
    EXPECT_TRUE(h.support().supported) << h.support().reason;
    h.setup();
    h.renderFrame();
    return h.readLayers();
}

ref::Accumulator renderReference(const Scene& scene, uint32_t spp,
                                 ref::PixelFilter filter = ref::PixelFilter::Box) {
    ref::ReferenceSettings settings;
    settings.maxBounces = 0;  // emission + direct
    settings.seed = 3;
    settings.pixelFilter = filter;
    // i.i.d. samples: the rules below take the GPU's 4 x 4 quadrature of the pixel box as the
    // same estimand, which holds within these error bars; the Sobol default's are ~10x smaller
    // on this direct light and expose the quadrature's own error (measured 2026-12-05: |diff| /
    // stderr mean 10.8, 6 pixels beyond 5 stderr + 1e-3 ref, mean |rel diff| still 7.4e-5)
    settings.sampler = ref::SamplerKind::Independent;
    ref::PathTracer tracer(scene, settings);
    ref::Accumulator acc;
    acc.reset(scene.settings.width, scene.settings.height);
    EXPECT_TRUE(tracer.addSamples(acc, spp));
    EXPECT_EQ(acc.nonFiniteSamples, 0u);
    return acc;
}

float lum(const Image& im, int x, int y) {
    return luminance(im.at(x, y, 0), im.at(x, y, 1), im.at(x, y, 2));
}

/** Box filter of factor x factor blocks: the GPU's pixel-centre samples -> pixel means. */
Image downsample(const Image& hi, int factor) {
    Image lo(hi.width() / factor, hi.height() / factor, hi.channels());
    for (int y = 0; y < lo.height(); ++y)
        for (int x = 0; x < lo.width(); ++x)
            for (int c = 0; c < hi.channels(); ++c) {
                double sum = 0.0;
                for (int j = 0; j < factor; ++j)
                    for (int i = 0; i < factor; ++i)
                        sum += hi.at(x * factor + i, y * factor + j, c);
                lo.at(x, y, c) = float(sum / (factor * factor));
            }
    return lo;
}

Scene cornell(const std::string& variant, int size) {
    Scene scene =
        variant.empty()
            ? makeBuiltinDefaultScene()
            : loadSceneFile(std::string(GILAB_SOURCE_DIR) + "/scenes/cornell_box.json", variant);
    scene.settings.width = size;
    scene.settings.height = size;
    return scene;
}

/**
 * Pixels where the GPU's box-filtered sub-pixel samples and the reference's box-filtered mean
 * must agree, all tested over the pixel's 3x3 neighbourhood (a margin of one pixel around any
 * discontinuity):
 *  - geometry: every GPU sub-sample is covered and shows the same plane (equal normals, 1/depth
 *    affine along rows and columns, as it is on a plane);
 *  - GPU shadows: every sub-sample's shadow-map visibility V = direct / unshadowed direct is
 *    exactly 0 or 1 (no PCF penumbra);
 *  - reference shadows: no neighbour differs from the pixel by more than 50% of it, which a
 *    lit/unlit edge (100%) always does and the smooth shading of the scene never does.
 */
std::vector<uint8_t> comparablePixels(const Image& refDirect, const std::vector<ImageLayer>& gpu,
                                      const std::vector<ImageLayer>& gpuUnshadowed, int factor) {
    const Image& direct = layer(gpu, "direct");
    const Image& unshadowed = layer(gpuUnshadowed, "direct");
    const Image& normal = layer(gpu, "normal");
    const Image& depth = layer(gpu, "depth");
    const int w = refDirect.width(), h = refDirect.height();
    std::vector<uint8_t> keep(size_t(w) * size_t(h), 0);
    for (int y = 1; y + 1 < h; ++y)
        for (int x = 1; x + 1 < w; ++x) {
            bool ok = true;
            const float r = lum(refDirect, x, y);
            for (int dy = -1; dy <= 1; ++dy)
                for (int dx = -1; dx <= 1; ++dx)
                    if (std::abs(lum(refDirect, x + dx, y + dy) - r) > 0.5f * r) ok = false;
            // The hi-res block of the 3x3 neighbourhood
            const int x0 = (x - 1) * factor, y0 = (y - 1) * factor, n = 3 * factor;
            for (int j = 0; j < n && ok; ++j)
                for (int i = 0; i < n && ok; ++i) {
                    const int hx = x0 + i, hy = y0 + j;
                    if (depth.at(hx, hy, 0) <= 0.0f) ok = false;
                    for (int c = 0; c < 3; ++c)
                        if (std::abs(normal.at(hx, hy, c) - normal.at(x0, y0, c)) > 1e-4f)
                            ok = false;
                    const float u = lum(unshadowed, hx, hy);
                    const float v = u > 0.0f ? lum(direct, hx, hy) / u : 0.0f;
                    if (v > 1e-6f && v < 1.0f - 1e-5f) ok = false;  // PCF penumbra
                    if (!ok || i == 0 || j == 0 || i == n - 1 || j == n - 1) continue;
                    const float inv = 1.0f / depth.at(hx, hy, 0);
                    for (auto [ox, oy] : {std::pair{1, 0}, std::pair{0, 1}}) {
                        const float d2 = 1.0f / depth.at(hx - ox, hy - oy, 0) +
                                         1.0f / depth.at(hx + ox, hy + oy, 0) - 2.0f * inv;
                        if (std::abs(d2) > 1e-3f * inv) ok = false;
                    }
                }
            keep[size_t(y * w + x)] = ok ? 1 : 0;
        }
    return keep;
}

struct Comparison {
    int lit = 0;           // compared pixels with reference light
    int dark = 0;          // compared pixels without (shadow, outside the cone)
    double meanRel = 0.0;  // mean of |gpu - ref| / ref over lit pixels (luminance)
    double maxRel = 0.0;
    double meanSigned = 0.0;   // mean of (gpu - ref) / ref: a systematic bias shows here
    double signedSigma = 0.0;  // its standard error from the reference's stderrs
    double meanSigmas = 0.0;   // mean of |gpu - ref| / ref stderr (0.80 for pure noise)
    double maxSigmas = 0.0;
    int outliers = 0;         // lit pixels with |gpu - ref| > 5 stderr + 1e-3 ref
    double maxDarkGpu = 0.0;  // largest GPU luminance where the reference is 0
};

Comparison compare(const Image& ref, const Image& refStdErr, const Image& gpu,
                   const std::vector<uint8_t>& keep) {
    Comparison c;
    double maxRef = 0.0;
    for (int y = 0; y < ref.height(); ++y)
        for (int x = 0; x < ref.width(); ++x)
            maxRef = std::max(maxRef, double(lum(ref, x, y)));
    for (int y = 0; y < ref.height(); ++y)
        for (int x = 0; x < ref.width(); ++x) {
            if (!keep[size_t(y * ref.width() + x)]) continue;
            const double r = lum(ref, x, y), g = lum(gpu, x, y);
            if (r > 1e-3 * maxRef) {
                const double rel = std::abs(g - r) / r;
                const double se = std::max(double(lum(refStdErr, x, y)), 1e-12);
                c.meanRel += rel;
                c.maxRel = std::max(c.maxRel, rel);
                c.meanSigned += (g - r) / r;
                c.signedSigma += (se / r) * (se / r);
                c.meanSigmas += std::abs(g - r) / se;
                c.maxSigmas = std::max(c.maxSigmas, std::abs(g - r) / se);
                if (std::abs(g - r) > 5.0 * se + 1e-3 * r) ++c.outliers;
                ++c.lit;
            } else if (r == 0.0) {
                c.maxDarkGpu = std::max(c.maxDarkGpu, g);
                ++c.dark;
            }
        }
    if (c.lit > 0) {
        c.meanRel /= c.lit;
        c.meanSigned /= c.lit;
        c.signedSigma = std::sqrt(c.signedSigma) / c.lit;
        c.meanSigmas /= c.lit;
    }
    return c;
}

TEST_F(GpuReferenceVsDirect, CornellSpotDirectAgrees) {
    constexpr int kSize = 64, kFactor = 4;
    constexpr uint32_t kSpp = 4096;
    const Scene scene = cornell("spot", kSize);
    const auto gpu = renderDirect(*m_ctx, scene, true, kFactor);
    const auto gpuUnshadowed = renderDirect(*m_ctx, scene, false, kFactor);
    const auto gpuCentres = renderDirect(*m_ctx, scene, true, 1);
    const ref::Accumulator acc = renderReference(scene, kSpp);
    const Image refDirect = ref::meanLayers(acc)[int(ref::Layer::Direct)].image;
    const Image refStdErr = ref::stdErrorLayers(acc)[int(ref::Layer::Direct)].image;
    const std::vector<uint8_t> keep = comparablePixels(refDirect, gpu, gpuUnshadowed, kFactor);

    // The GPU box-filtered from 4 x 4 centre samples per pixel: the same estimand
    const Comparison c =
        compare(refDirect, refStdErr, downsample(layer(gpu, "direct"), kFactor), keep);
    // The plain 64 x 64 centre samples: adds the centre-vs-box difference (curvature)
    const Comparison centres = compare(refDirect, refStdErr, layer(gpuCentres, "direct"), keep);
    std::printf(
        "[ measured ] cornell spot %dx%d, reference %u spp: %d lit + %d dark of %d pixels "
        "compared\n"
        "[ measured ]   GPU 4x4 box: |rel diff| mean %.2e max %.2e; signed mean %+.2e +- %.1e; "
        "|diff| / ref stderr mean %.2f max %.2f; outliers %d\n"
        "[ measured ]   GPU centres: |rel diff| mean %.2e max %.2e; signed mean %+.2e\n"
        "[ measured ]   max GPU value where the reference is 0: %.2e (box), %.2e (centres)\n",
        kSize, kSize, kSpp, c.lit, c.dark, kSize * kSize, c.meanRel, c.maxRel, c.meanSigned,
        c.signedSigma, c.meanSigmas, c.maxSigmas, c.outliers, centres.meanRel, centres.maxRel,
        centres.meanSigned, c.maxDarkGpu, centres.maxDarkGpu);
    EXPECT_GT(c.lit, kSize * kSize / 6);
    EXPECT_GT(c.dark, kSize * kSize / 6);
    // Box vs box: agreement to the reference's noise, no bias, no light where it has none
    EXPECT_EQ(c.outliers, 0);
    EXPECT_LT(std::abs(c.meanSigned), 4.0 * c.signedSigma + 2e-4);
    EXPECT_LT(c.meanRel, 1e-3);
    EXPECT_EQ(c.maxDarkGpu, 0.0);
    // Centre samples: adds the box filter's curvature term (up to a few % in the spot's
    // t^2 falloff); the mean stays small
    EXPECT_LT(centres.meanRel, 4e-3);
    EXPECT_EQ(centres.maxDarkGpu, 0.0);

    // No emitter in this variant: both emission layers are exactly 0
    for (float v : layer(gpuCentres, "emission").values())
        ASSERT_EQ(v, 0.0f);
    for (int y = 0; y < kSize; ++y)
        for (int x = 0; x < kSize; ++x)
            for (int ch = 0; ch < 3; ++ch)
                ASSERT_EQ(acc.mean(ref::Layer::Emission, x, y, ch), 0.0);
}

TEST_F(GpuReferenceVsDirect, CornellAreaLightEmissionAgrees) {
    // 128 x 128: the ceiling light, seen at a grazing angle, is ~4 pixels tall
    constexpr int kSize = 128;
    const Scene scene = cornell("", kSize);
    const auto gpu = renderDirect(*m_ctx, scene, true, 1);
    const ref::Accumulator acc = renderReference(scene, 64);
    const std::vector<ImageLayer> refLayers = ref::meanLayers(acc);
    const Image& refE = refLayers[int(ref::Layer::Emission)].image;
    const Image& gpuE = layer(gpu, "emission");
    // Compare where every reference sample hit the light (mean == Le exactly) and where the
    // reference's 3 x 3 neighbourhood saw none of it
    const glm::vec3 le =
        scene.materials[scene.triangleMaterials[scene.triangleCount() - 1]].emissiveFactor;
    int lightPixels = 0, darkPixels = 0;
    double maxDiff = 0.0;
    for (int y = 1; y + 1 < kSize; ++y)
        for (int x = 1; x + 1 < kSize; ++x) {
            bool full = true, none = true;
            for (int c = 0; c < 3; ++c)
                full = full && refE.at(x, y, c) == le[c];
            for (int dy = -1; dy <= 1; ++dy)
                for (int dx = -1; dx <= 1; ++dx)
                    none = none && refE.at(x + dx, y + dy, 0) == 0.0f;
            if (!full && !none) continue;
            (full ? lightPixels : darkPixels)++;
            for (int c = 0; c < 3; ++c)
                maxDiff = std::max(maxDiff, double(std::abs(gpuE.at(x, y, c) - refE.at(x, y, c))));
        }
    std::printf(
        "[ measured ] cornell emission %dx%d: %d light + %d other pixels compared, max "
        "|diff| %.2e\n",
        kSize, kSize, lightPixels, darkPixels, maxDiff);
    EXPECT_GT(lightPixels, 10);
    EXPECT_EQ(maxDiff, 0.0);

    // Information only: K emitter samples (shared passes) against the exact area light
    const Image& refDirect = refLayers[int(ref::Layer::Direct)].image;
    const Image& gpuDirect = layer(gpu, "direct");
    double sumRef = 0.0, sumGpu = 0.0;
    for (int y = 0; y < kSize; ++y)
        for (int x = 0; x < kSize; ++x) {
            sumRef += lum(refDirect, x, y);
            sumGpu += lum(gpuDirect, x, y);
        }
    std::printf(
        "[ measured ] cornell area light, image-mean direct: GPU (K emitter samples) / "
        "reference = %.4f\n",
        sumGpu / sumRef);
}

// Two emitter quads cut from one texture of a bright and a dim half (4 x 1 texels, clamped): the
// left quad's uvs span the bright texels, the right one's the dim texels, so each emits a
// constant radiance that the texture's mean (the average of both) misstates by +-60 %. The
// exact area-light irradiance uses each triangle's own mean (core/scene/emission.h); the floor
// under both must agree with the path tracer to its noise.
Scene texturedEmitters(int size) {
    Scene s;
    s.name = "textured_emitters";
    s.sourcePath = "<test>";
    s.settings.width = s.settings.height = size;
    Texture tex;
    tex.name = "<bright | dim>";
    tex.width = 4;
    tex.height = 1;
    tex.colorSpace = ColorSpace::Linear;
    tex.wrapU = tex.wrapV = WrapMode::ClampToEdge;
    for (uint8_t v : {255, 255, 51, 51})
        tex.rgba.insert(tex.rgba.end(), {v, v, v, 255});
    s.textures.push_back(tex);
    Material floor;
    floor.baseColorFactor = glm::vec4(0.8f, 0.8f, 0.8f, 1.0f);
    Material light;
    light.baseColorFactor = glm::vec4(0.0f, 0.0f, 0.0f, 1.0f);
    light.emissiveFactor = glm::vec3(4.0f);
    light.emissiveTexture = 0;
    s.materials = {floor, light};
    appendQuad(s, {-1, 0, -1}, {1, 0, -1}, {1, 0, 1}, {-1, 0, 1}, {0, 1, 0}, 0);
    for (const float u0 : {0.0f, 0.75f}) {
        const float x0 = u0 == 0.0f ? -0.45f : 0.05f;
        const size_t first = s.vertices.size();
        appendQuad(s, {x0, 0.35f, -0.2f}, {x0 + 0.4f, 0.35f, -0.2f}, {x0 + 0.4f, 0.35f, 0.2f},
                   {x0, 0.35f, 0.2f}, {0, -1, 0}, 1);
        for (size_t v = first; v < s.vertices.size(); ++v)
            s.vertices[v].uv.x = u0 + 0.25f * s.vertices[v].uv.x;
    }
    s.camera.position = {0.0f, 1.4f, 1.4f};
    s.camera.target = {0.0f, 0.0f, 0.0f};
    s.camera.up = {0.0f, 1.0f, 0.0f};
    s.camera.vfovRad = glm::radians(50.0f);
    s.computeCaps();
    return s;
}

TEST_F(GpuReferenceVsDirect, TexturedEmitterUsesEachTrianglesMeanRadiance) {
    constexpr int kSize = 48, kFactor = 4;
    constexpr uint32_t kSpp = 2048;
    const Scene scene = texturedEmitters(kSize);
    const auto gpu = renderDirect(*m_ctx, scene, true, kFactor);
    const auto gpuUnshadowed = renderDirect(*m_ctx, scene, false, kFactor);
    const ref::Accumulator acc = renderReference(scene, kSpp);
    const Image refDirect = ref::meanLayers(acc)[int(ref::Layer::Direct)].image;
    const Image refStdErr = ref::stdErrorLayers(acc)[int(ref::Layer::Direct)].image;
    const std::vector<uint8_t> keep = comparablePixels(refDirect, gpu, gpuUnshadowed, kFactor);
    const Image gpuDirect = downsample(layer(gpu, "direct"), kFactor);
    const Comparison c = compare(refDirect, refStdErr, gpuDirect, keep);
    // The floor under each emitter: left (bright) and right (dim) halves of the image
    double left = 0.0, leftRef = 0.0, right = 0.0, rightRef = 0.0;
    for (int y = 0; y < kSize; ++y)
        for (int x = 0; x < kSize; ++x) {
            if (!keep[size_t(y * kSize + x)]) continue;
            (x < kSize / 2 ? left : right) += lum(gpuDirect, x, y);
            (x < kSize / 2 ? leftRef : rightRef) += lum(refDirect, x, y);
        }
    std::printf(
        "[ measured ] textured emitters %dx%d, reference %u spp: %d lit pixels compared; "
        "|rel diff| mean %.2e max %.2e; signed mean %+.2e +- %.1e; outliers %d; "
        "GPU / reference under the bright quad's side %.4f, the dim one's %.4f\n",
        kSize, kSize, kSpp, c.lit, c.meanRel, c.maxRel, c.meanSigned, c.signedSigma, c.outliers,
        left / leftRef, right / rightRef);
    EXPECT_GT(c.lit, kSize * kSize / 3);
    EXPECT_LT(std::abs(c.meanSigned), 4.0 * c.signedSigma + 2e-3);
    EXPECT_NEAR(left / leftRef, 1.0, 0.01);
    EXPECT_NEAR(right / rightRef, 1.0, 0.01);
    EXPECT_LE(c.outliers, c.lit / 100);
}

// ---------------------------------------------------------------------------------------------
// The shared direct light at the rasteriser's own footprint (issue 27's acceptance): the direct
// technique's emission + direct against the path tracer's at the centre filter, at the scene's
// default resolution. Energy within 2 %, and less than 0.5 % of the light in pixels the path
// tracer has in shadow (docs/shared_passes.md, "Accuracy").
// ---------------------------------------------------------------------------------------------

metrics::DirectAccuracy directAccuracyOf(vk::Context& ctx, const Scene& scene) {
    FrameHarness h(ctx, scene, "direct", TechniqueRegistry::instance().defaultParams("direct"),
                   defaultSharedParams());
    EXPECT_TRUE(h.support().supported) << h.support().reason;
    h.setup();
    h.renderFrame();
    const auto layers = h.readLayers();
    Image raster = layer(layers, "direct");
    for (size_t i = 0; i < raster.values().size(); ++i)
        raster.values()[i] += layer(layers, "emission").values()[i];
    // Delta lights only: one centre sample per pixel is exact
    const ref::Accumulator acc = renderReference(scene, 1, ref::PixelFilter::Center);
    const auto refLayers = ref::meanLayers(acc);
    Image reference = refLayers[int(ref::Layer::Direct)].image;
    for (size_t i = 0; i < reference.values().size(); ++i)
        reference.values()[i] += refLayers[int(ref::Layer::Emission)].image.values()[i];
    const metrics::DirectAccuracy a = metrics::directAccuracy(raster, reference);
    std::printf("[ measured ] %s %dx%d: energy %.4f, leak %.3f %%, missing %.3f %%\n",
                scene.name.c_str(), scene.settings.width, scene.settings.height, a.energyRatio,
                100.0 * a.shadowLeak, 100.0 * a.missing);
    return a;
}

TEST_F(GpuReferenceVsDirect, SpotBoxEnergyAndLeaksAtTheRasterFootprint) {
    const Scene scene =
        loadSceneFile(std::string(GILAB_SOURCE_DIR) + "/scenes/cornell_box.json", "spot");
    const metrics::DirectAccuracy a = directAccuracyOf(*m_ctx, scene);
    EXPECT_NEAR(a.energyRatio, 1.0, 0.02);
    EXPECT_LT(a.shadowLeak, 0.005);
    EXPECT_GT(a.shadowPixels, size_t(1000));  // the blocks' shadows and outside the cone
}

// Lights away from the shipped placements (issue 43; `gilab bench direct --placements`): random
// point and spot lights near walls and in corners of the box and of the near-wall stress room
// (light_placements.h, seed 1). Measured with 20 placements per scene: box leak median 0.002 %,
// worst 0.085 %, energy 0.9992-1.0008; near-wall room worst 0.035 %, energy 0.9990-1.0046. Each
// placement here must meet the bench's p95 target (leak <= 1 %) and its energy (+-2 %).
TEST_F(GpuReferenceVsDirect, RandomPointAndSpotPlacementsStayWithinTheBenchTargets) {
    for (const char* file :
         {"/scenes/cornell_box.json", "/scenes/stress/point_light_near_wall.json"}) {
        Scene scene = loadSceneFile(std::string(GILAB_SOURCE_DIR) + file);
        scene.settings.width = 64;
        scene.settings.height = 64;
        const std::vector<cli::LightPlacement> placements = cli::randomLightPlacements(scene, 1, 6);
        ASSERT_EQ(placements.size(), 6u) << file;
        for (const cli::LightPlacement& p : placements) {
            const metrics::DirectAccuracy a =
                directAccuracyOf(*m_ctx, cli::withOnlyLight(scene, p.light));
            if (!std::isfinite(a.energyRatio)) continue;  // the camera sees nothing it lights
            EXPECT_NEAR(a.energyRatio, 1.0, 0.02) << file << " " << p.label;
            EXPECT_LT(a.shadowLeak, 0.01) << file << " " << p.label;
        }
    }
}

/** A square [-1, 1]^2 in y = 0 seen from above (its seen side faces +y), shading normals tilted
 *  toward +x, lit by a point light just below its plane: the light is behind the seen side,
 *  yet n . wi > 0 for the shading normal (issue 43 item 5: 63 % of the leak of the issue's
 *  Sibenik case). */
Scene lightBehindTheSeenSide() {
    Scene s;
    s.name = "light_behind_the_seen_side";
    s.sourcePath = "<test>";
    appendLambertianMaterial(s, "grey", glm::vec3(0.5f));
    appendQuad(s, {-1, 0, -1}, {1, 0, -1}, {1, 0, 1}, {-1, 0, 1}, {0, 1, 0}, 0);
    for (Vertex& v : s.vertices)
        v.normal = glm::normalize(glm::vec3(1.0f, 0.2f, 0.0f));
    Light l;
    l.type = LightType::Point;
    l.position = {4.0f, -0.3f, 0.0f};
    l.intensity = glm::vec3(10.0f);
    l.color = l.intensity;
    s.lights.push_back(l);
    s.camera.position = {0.0f, 3.0f, 0.0f};
    s.camera.target = {0.0f, 0.0f, 0.0f};
    s.camera.up = {0.0f, 0.0f, -1.0f};
    s.camera.vfovRad = 0.9f;
    s.settings.width = 32;
    s.settings.height = 32;
    s.computeCaps();
    return s;
}

// The path tracer gives no light to a surface whose seen side faces away from the light
// (integrator.cpp: ng . wi <= 0), whatever its shading normal; the direct pass must agree.
// Fails without the geometric-side test of direct_light.comp (every pixel lit).
TEST_F(GpuReferenceVsDirect, ALightBehindTheSeenSideLightsNothingWhateverTheShadingNormal) {
    const Scene scene = lightBehindTheSeenSide();
    const Image ref = ref::meanLayers(renderReference(scene, 1))[int(ref::Layer::Direct)].image;
    for (bool shadows : {true, false}) {
        const std::vector<ImageLayer> layers = renderDirect(*m_ctx, scene, shadows, 1);
        const Image& direct = layer(layers, "direct");
        size_t covered = 0, lit = 0;
        for (int y = 0; y < direct.height(); ++y)
            for (int x = 0; x < direct.width(); ++x) {
                EXPECT_EQ(lum(ref, x, y), 0.0f);
                ++covered;
                if (lum(direct, x, y) > 0.0f) ++lit;
            }
        EXPECT_EQ(lit, 0u) << "shadows " << shadows << ": " << lit << " of " << covered;
    }
}

/** A floor y = 0 seen from above, a square occluder [-0.4, 0.4]^2 at height `occluderY` (0:
 *  none) and a point light at `light`. */
Scene occluderScene(float occluderY, glm::vec3 light) {
    Scene s = lightBehindTheSeenSide();
    s.vertices.clear();
    s.indices.clear();
    s.triangleMaterials.clear();
    appendQuad(s, {-2, 0, -2}, {2, 0, -2}, {2, 0, 2}, {-2, 0, 2}, {0, 1, 0}, 0);
    if (occluderY > 0.0f)
        appendQuad(s, {-0.4f, occluderY, -0.4f}, {0.4f, occluderY, -0.4f}, {0.4f, occluderY, 0.4f},
                   {-0.4f, occluderY, 0.4f}, {0, 1, 0}, 0);
    s.lights[0].position = light;
    s.settings.width = s.settings.height = 48;
    s.computeCaps();
    return s;
}

/** The classification of a raster that lights every covered pixel (1 everywhere) against the
 *  path tracer's direct light, for a shadow map of `resolution` texels per side. */
cli::LeakCauses leaksOfAFullyLitRaster(const Scene& scene, uint32_t resolution) {
    const Image ref = ref::meanLayers(renderReference(
        scene, 1, ref::PixelFilter::Center))[int(ref::Layer::Direct)]
                          .image;
    Image raster(ref.width(), ref.height(), ref.channels());
    for (float& v : raster.values())
        v = 1.0f;
    cli::ShadowModel model;
    model.resolution = resolution;
    return cli::classifyLeaks(scene, raster, ref, model);
}

// `gilab bench direct` names the cause of a leak (leak_causes.h, issue 43 item 5); each cause
// is built here and must come out as the largest share.
TEST(CpuLeakCauses, EachConstructedCauseIsNamed) {
    // An occluder 0.3 m above the floor, the light 3 m off to the side: with 64 texels (about
    // 0.13 m at the floor) the map holds it (its shadow's inside is "unexplained"; the pixels
    // within half a texel of its outline are "texel edge") ...
    const Scene scene = occluderScene(0.3f, {3, 3, 0});
    const cli::LeakCauses held = leaksOfAFullyLitRaster(scene, 64);
    ASSERT_GT(held.pixels, 30u);
    EXPECT_GT(held.unexplained, 0.5 * held.total);
    EXPECT_GT(held.texelEdge, 0.0);
    EXPECT_EQ(held.contact + held.backFacing + held.notOccluded + held.nearPlane, 0.0);
    // ... with 16 texels (0.35 m at the floor) the gap is inside the bias margin: contact
    const cli::LeakCauses coarse = leaksOfAFullyLitRaster(scene, 16);
    EXPECT_EQ(coarse.pixels, held.pixels);
    EXPECT_GT(coarse.contact, 0.9 * coarse.total);
    // The light below the floor's plane: every seen pixel faces away from it
    const cli::LeakCauses behind = leaksOfAFullyLitRaster(occluderScene(0.0f, {3, -0.5f, 0}), 1024);
    ASSERT_GT(behind.pixels, 500u);
    EXPECT_EQ(behind.backFacing, behind.total);
}

TEST_F(GpuReferenceVsDirect, SponzaSunEnergyAndLeaksAtTheRasterFootprint) {
    Scene scene;
    try {
        scene = loadSceneFile(std::string(GILAB_SOURCE_DIR) + "/scenes/sponza.json");
    } catch (const Error& e) {
        GTEST_SKIP() << "shared scene not available: " << e.what();
    }
    const metrics::DirectAccuracy a = directAccuracyOf(*m_ctx, scene);
    EXPECT_NEAR(a.energyRatio, 1.0, 0.02);
    EXPECT_LT(a.shadowLeak, 0.005);
    EXPECT_GT(a.shadowPixels, size_t(10000));
}

}  // namespace
}  // namespace gilab
