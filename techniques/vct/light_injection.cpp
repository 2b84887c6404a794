#include "light_injection.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <optional>

#include "core/gpu/gpu_scene.h"
#include "core/passes/light_view.h"
#include "core/passes/shared_passes.h"
#include "core/scene/scene.h"
#include "core/technique/technique.h"
#include "core/util/error.h"
#include "core/vk/barrier.h"
#include "core/vk/context.h"
#include "core/vk/rendering.h"

namespace gilab::vct {
namespace {

constexpr VkFormat kPositionFormat = VK_FORMAT_R32G32B32A32_SFLOAT;
constexpr VkFormat kNormalFormat = VK_FORMAT_R16G16B16A16_SFLOAT;
constexpr VkFormat kDepthFormat = VK_FORMAT_D32_SFLOAT;
constexpr uint32_t kMinMapSide = 8;
/** Above this many batches only the first batch's steps are timed one by one. */
constexpr uint32_t kMaxTimedBatches = 8;
constexpr uint32_t kModeCount = 0, kModeIrradiance = 1;

/** Mirrors InjectPush in techniques/vct/shaders/inject_common.glsl. */
struct InjectPush {
    GpuVoxelGrid grid;
    glm::vec4 scale{0.0f};  // x flux units per W, y W per unit, z irradiance units per W/m^2, w inv
    glm::uvec4 counts{0u};  // x photons, y first photon, z mode
    glm::uvec4 light{0u};   // x first view of the light, y its view count
    glm::vec4 params{0.0f};  // x irradiance cap per photon (fixed point)
};
static_assert(sizeof(InjectPush) == 96);

/** Mirrors LightViewPush in techniques/vct/shaders/light_view.glsl. */
struct LightViewPush {
    glm::mat4 viewProj{1.0f};
    glm::vec4 toLight{0.0f};    // xyz light position (w 0) or unit direction toward it (w 1)
    glm::vec4 skipPlane{0.0f};  // xyz unit normal, w offset
    glm::vec4 skip{0.0f};       // x skip distance (0 = none)
};
static_assert(sizeof(LightViewPush) == 112);

/** Orthographic: ndc = (x.(p - c) / hx, y.(p - c) / hy); depth = 1 - distance from the entry
 *  plane / (2r) (reversed Z), entry plane through c - f r. */
glm::mat4 orthoViewProj(const glm::vec3& c, const glm::vec3& f, const glm::vec3& x,
                        const glm::vec3& y, float hx, float hy, float r) {
    glm::mat4 m(0.0f);
    const glm::vec3 entry = c - f * r;
    for (int i = 0; i < 3; ++i) {
        m[i][0] = x[i] / hx;
        m[i][1] = y[i] / hy;
        m[i][2] = -f[i] / (2.0f * r);
    }
    m[3][0] = -glm::dot(x, c) / hx;
    m[3][1] = -glm::dot(y, c) / hy;
    m[3][2] = 1.0f + glm::dot(f, entry) / (2.0f * r);
    m[3][3] = 1.0f;
    return m;
}

/**
 * Pinhole window [cx - hx, cx + hx] x [cy - hy, cy + hy] on the unit-distance image plane of
 * normal m (unit axes s, t) seen from `eye`: clip = ((s - cx m).q / hx, (t - cy m).q / hy, near,
 * m.q) with q = p - eye (reversed Z, infinite far). With cx = cy = 0 and hx = hy = tan(half fov)
 * this is pinholeViewProj of core/passes/light_view.h.
 */
glm::mat4 windowViewProj(const glm::vec3& eye, const glm::vec3& m, const glm::vec3& s,
                         const glm::vec3& t, float cx, float cy, float hx, float hy, float nearZ) {
    glm::mat4 out(0.0f);
    const glm::vec3 sx = (s - cx * m) / hx, ty = (t - cy * m) / hy;
    for (int i = 0; i < 3; ++i) {
        out[i][0] = sx[i];
        out[i][1] = ty[i];
        out[i][3] = m[i];
    }
    out[3][0] = -glm::dot(sx, eye);
    out[3][1] = -glm::dot(ty, eye);
    out[3][2] = nearZ;
    out[3][3] = -glm::dot(m, eye);
    return out;
}

GpuLightView pinholeView(const GpuLightView& base, const glm::vec3& eye, const glm::vec3& m,
                         const glm::vec3& s, const glm::vec3& t, float cx, float cy, float hx,
                         float hy, float nearZ) {
    GpuLightView v = base;
    v.viewProj = windowViewProj(eye, m, s, t, cx, cy, hx, hy, nearZ);
    v.positionKind = glm::vec4(eye, 0.0f);
    v.forward = glm::vec4(m + cx * s + cy * t, 0.0f);
    v.axisX = glm::vec4(s * hx, hx);
    v.axisY = glm::vec4(t * hy, hy);
    return v;
}

void basisFor(const glm::vec3& f, glm::vec3& x, glm::vec3& y) {
    const glm::vec3 up = std::abs(f.y) < 0.99f ? glm::vec3(0, 1, 0) : glm::vec3(1, 0, 0);
    x = glm::normalize(glm::cross(f, up));
    y = glm::cross(f, x);  // right-handed (x, y, f); y points "down" in the map
}

bool isOrtho(const GpuLightView& v) {
    return v.positionKind.w > 0.5f;
}

/** Unit normal of a pinhole view's image plane, on the side of its rays. */
glm::dvec3 planeNormal(const GpuLightView& v) {
    glm::dvec3 m = glm::normalize(glm::cross(glm::dvec3(v.axisX), glm::dvec3(v.axisY)));
    if (glm::dot(m, glm::dvec3(v.forward)) < 0.0) m = -m;
    return m;
}

/** Distance from a pinhole view's eye to the farthest grid corner in front of its image plane
 *  (0 when the grid is entirely behind it). */
double farthestGridCorner(const GpuLightView& v, const VoxelGrid& grid) {
    const glm::dvec3 m = planeNormal(v);
    const glm::dvec3 eye(v.positionKind);
    double far = 0.0;
    for (int k = 0; k < 8; ++k) {
        const glm::dvec3 c = glm::dvec3(grid.origin()) +
                             double(grid.side()) * glm::dvec3(k & 1, (k >> 1) & 1, (k >> 2) & 1);
        if (glm::dot(m, c - eye) > 0.0) far = std::max(far, glm::length(c - eye));
    }
    return far;
}

/** Largest texel footprint of a sized view on the farthest grid corner, in voxels. */
double texelFootprintVoxels(const GpuLightView& v, const VoxelGrid& grid) {
    const double tx = 2.0 * double(v.axisX.w) / std::max(v.texels.x, 1u);
    const double ty = 2.0 * double(v.axisY.w) / std::max(v.texels.y, 1u);
    if (isOrtho(v)) return std::max(tx, ty) / double(grid.voxelSize());
    const double d = std::abs(glm::dot(planeNormal(v), glm::dvec3(v.forward)));
    return std::max(tx, ty) / d * farthestGridCorner(v, grid) / double(grid.voxelSize());
}

uint64_t texelCount(const GpuLightView& v) {
    return uint64_t(v.texels.x) * v.texels.y;
}

uint64_t photonsOf(const std::vector<GpuLightView>& views, uint32_t first, uint32_t count) {
    uint64_t n = 0;
    for (uint32_t i = first; i < first + count; ++i)
        n += texelCount(views[i]);
    return n;
}

/** Scales the sizes of views [first, first + count) until their photons fit in `budget`. */
void shrinkToFit(std::vector<GpuLightView>& views, uint32_t first, uint32_t count,
                 uint64_t budget) {
    uint64_t n = photonsOf(views, first, count);
    for (int iter = 0; n > budget && iter < 64; ++iter) {
        const double f = std::min(0.99, std::sqrt(double(budget) / double(n)));
        for (uint32_t i = first; i < first + count; ++i) {
            GpuLightView& v = views[i];
            v.texels.x = std::max(kMinMapSide, uint32_t(std::floor(double(v.texels.x) * f)));
            v.texels.y = std::max(kMinMapSide, uint32_t(std::floor(double(v.texels.y) * f)));
        }
        n = photonsOf(views, first, count);
    }
}

std::string lightName(const GpuLightView& v) {
    const int index = int(std::lround(v.cone.z));
    if (index < 0) return "emitter sample " + std::to_string(-1 - index);
    return "light " + std::to_string(index);
}

std::string fixed2(double x) {
    char text[32];
    std::snprintf(text, sizeof(text), "%.2f", x);
    return text;
}

}  // namespace

std::vector<GpuLightView> buildLightViews(const Scene& scene, const VoxelGrid& grid,
                                          const std::vector<EmitterSample>& samples) {
    std::vector<GpuLightView> views;
    const glm::vec3 centre = grid.origin() + glm::vec3(0.5f * grid.side());
    const float radius = 0.5f * std::sqrt(3.0f) * grid.side() * 1.01f;
    const float nearZ = 1e-3f * grid.voxelSize();
    uint32_t light = 0;
    auto endLight = [&](size_t first) {
        for (size_t i = first; i < views.size(); ++i) {
            views[i].group = glm::uvec4(light, uint32_t(first), uint32_t(views.size() - first), 0u);
        }
        ++light;
    };
    for (size_t li = 0; li < scene.lights.size(); ++li) {
        const Light& l = scene.lights[li];
        const size_t first = views.size();
        const glm::vec3 dir =
            glm::length(l.direction) > 0.0f ? glm::normalize(l.direction) : glm::vec3(0, -1, 0);
        GpuLightView base;
        base.intensity = glm::vec4(l.intensity, float(kLobeUniform));
        base.cone = glm::vec4(std::cos(l.innerConeRad), std::cos(l.outerConeRad), float(li), 0.0f);
        if (l.type == LightType::Directional) {
            // Orthographic window fitted to the grid's projection; depth over its bounding sphere
            glm::vec3 x, y;
            basisFor(dir, x, y);
            const glm::vec3 ax = glm::abs(x), ay = glm::abs(y);
            const float hx = 0.5f * grid.side() * (ax.x + ax.y + ax.z) * 1.01f;
            const float hy = 0.5f * grid.side() * (ay.x + ay.y + ay.z) * 1.01f;
            GpuLightView v = base;
            v.viewProj = orthoViewProj(centre, dir, x, y, hx, hy, radius);
            v.positionKind = glm::vec4(centre, 1.0f);
            v.forward = glm::vec4(dir, 0.0f);
            v.axisX = glm::vec4(x * hx, hx);
            v.axisY = glm::vec4(y * hy, hy);
            views.push_back(v);
            endLight(first);
            continue;
        }
        const bool spot = l.type == LightType::Spot;
        if (spot) {
            base.spotAxis = glm::vec4(dir, 1.0f);
            base.intensity.w = float(kLobeSpot);
        }
        if (spot && glm::degrees(l.outerConeRad) <= kSpotCubeOuterDeg) {
            // One perspective map whose square just contains the outer cone
            const float tanHalf = std::tan(std::max(l.outerConeRad, 1e-3f));
            glm::vec3 x, y;
            basisFor(dir, x, y);
            views.push_back(
                pinholeView(base, l.position, dir, x, y, 0.0f, 0.0f, tanHalf, tanHalf, nearZ));
            endLight(first);
            continue;
        }
        for (const CubeFace& face : kCubeFaces) {
            views.push_back(pinholeView(base, l.position, face.m, face.s, face.t, 0.0f, 0.0f, 1.0f,
                                        1.0f, nearZ));
        }
        endLight(first);
    }

    // Emitter samples: cosine-lobe point lights I(w) = Le A_k max(0, n.w) (|n.w| double-sided),
    // exactly as the direct pass evaluates them (docs/shared_passes.md). A hemicube covers the
    // lobe: the front face (normal n) and the halves of the 4 side faces on n's side; a
    // double-sided sample gets the 6 full cube faces. The sample's own plane is not rendered.
    const float skipDistance = 1e-4f * 0.5f * std::sqrt(3.0f) * grid.side();
    for (size_t k = 0; k < samples.size(); ++k) {
        const EmitterSample& s = samples[k];
        const size_t first = views.size();
        const glm::vec3 n = glm::normalize(s.normal);
        GpuLightView base;
        base.intensity =
            glm::vec4(s.intensity, float(s.twoSided ? kLobeCosineTwoSided : kLobeCosine));
        base.spotAxis = glm::vec4(n, 0.0f);
        base.cone = glm::vec4(0.0f, 0.0f, -1.0f - float(k), skipDistance);
        base.skipPlane = glm::vec4(n, -glm::dot(n, s.position));
        if (s.twoSided) {
            for (const CubeFace& face : kCubeFaces) {
                views.push_back(pinholeView(base, s.position, face.m, face.s, face.t, 0.0f, 0.0f,
                                            1.0f, 1.0f, nearZ));
            }
        } else {
            glm::vec3 a, b;
            basisFor(n, a, b);
            views.push_back(pinholeView(base, s.position, n, a, b, 0.0f, 0.0f, 1.0f, 1.0f, nearZ));
            const glm::vec3 sideAxis[4] = {a, -a, b, -b};
            const glm::vec3 across[4] = {b, b, a, a};
            for (int i = 0; i < 4; ++i) {
                // Rays sideAxis + u across + v n, u in [-1, 1], v in [0, 1]
                views.push_back(pinholeView(base, s.position, sideAxis[i], across[i], n, 0.0f, 0.5f,
                                            1.0f, 0.5f, nearZ));
            }
        }
        endLight(first);
    }
    return views;
}

glm::dvec3 lightViewFluxBound(const GpuLightView& view) {
    const glm::dvec3 intensity(view.intensity);
    if (isOrtho(view))
        return intensity * (2.0 * double(view.axisX.w)) * (2.0 * double(view.axisY.w));
    // Solid angle of the window on the unit-distance plane: F(x, y) = atan(xy / sqrt(1 + x^2 +
    // y^2)) is the solid angle of [0, x] x [0, y]; inclusion-exclusion over the window's corners
    const glm::dvec3 m = planeNormal(view);
    const glm::dvec3 f(view.forward);
    const double d = glm::dot(f, m);
    const double hx = double(view.axisX.w) / d, hy = double(view.axisY.w) / d;
    const double cx = glm::dot(f, glm::dvec3(view.axisX) / double(view.axisX.w)) / d;
    const double cy = glm::dot(f, glm::dvec3(view.axisY) / double(view.axisY.w)) / d;
    auto F = [](double x, double y) { return std::atan(x * y / std::sqrt(1.0 + x * x + y * y)); };
    const double omega =
        F(cx + hx, cy + hy) - F(cx - hx, cy + hy) - F(cx + hx, cy - hy) + F(cx - hx, cy - hy);
    return intensity * omega;
}

glm::uvec2 footprintResolution(const GpuLightView& view, const VoxelGrid& grid) {
    const double target = double(kTexelFootprintVoxels) * double(grid.voxelSize());
    double wx = 2.0 * double(view.axisX.w), wy = 2.0 * double(view.axisY.w);
    if (!isOrtho(view)) {
        // A texel of size t on the unit-distance plane subtends at most t radians; on a surface
        // at distance D its footprint is at most t D (at normal incidence)
        const double far = farthestGridCorner(view, grid);
        if (!(far > 0.0)) return glm::uvec2(kMinMapSide);
        const double d = std::abs(glm::dot(planeNormal(view), glm::dvec3(view.forward)));
        wx *= far / d;
        wy *= far / d;
    }
    auto side = [&](double extent) {
        return uint32_t(std::max(double(kMinMapSide), std::ceil(extent / target - 1e-6)));
    };
    return glm::uvec2(side(wx), side(wy));
}

LightViewPlan planLightViews(std::vector<GpuLightView> views, const VoxelGrid& grid,
                             uint32_t mapResolution, const LightViewLimits& limits) {
    LightViewPlan plan;
    plan.views = std::move(views);
    std::vector<GpuLightView>& v = plan.views;

    // Sizes
    const uint32_t maxSide = std::max(limits.maxImageDimension, kMinMapSide);
    uint32_t imageClamped = 0;
    for (GpuLightView& view : v) {
        glm::uvec2 res;
        if (mapResolution == 0) {
            res = footprintResolution(view, grid);
        } else {
            // mapResolution texels along the window's longer side, square texels
            const double perUnit =
                double(mapResolution) / (2.0 * double(std::max(view.axisX.w, view.axisY.w)));
            res.x = std::max(kMinMapSide,
                             uint32_t(std::ceil(2.0 * double(view.axisX.w) * perUnit - 1e-6)));
            res.y = std::max(kMinMapSide,
                             uint32_t(std::ceil(2.0 * double(view.axisY.w) * perUnit - 1e-6)));
        }
        if (res.x > maxSide || res.y > maxSide) ++imageClamped;
        view.texels = glm::uvec4(std::min(res.x, maxSide), std::min(res.y, maxSide), 0u, 0u);
    }
    if (imageClamped > 0) {
        plan.notes.push_back(
            "light_map_resolution: " + std::to_string(imageClamped) +
            " light-view maps clamped to maxImageDimension2D = " + std::to_string(maxSide));
    }

    // Lights (their views are contiguous) and the photon budget of one buffer
    plan.lightCount = v.empty() ? 0u : v.back().group.x + 1u;
    const uint64_t budget = std::max<uint64_t>(limits.photonBufferBytes / sizeof(GpuPhoton),
                                               kMinMapSide * kMinMapSide * 6);
    const std::string budgetText = std::to_string(limits.photonBufferBytes >> 20) + " MiB";
    for (uint32_t i = 0; i < v.size(); i += v[i].group.z) {
        const uint32_t count = v[i].group.z;
        const uint64_t before = photonsOf(v, i, count);
        if (before <= budget) continue;
        shrinkToFit(v, i, count, budget);
        double footprint = 0.0;
        for (uint32_t j = i; j < i + count; ++j)
            footprint = std::max(footprint, texelFootprintVoxels(v[j], grid));
        plan.notes.push_back("light_map_resolution: " + lightName(v[i]) + "'s maps shrunk from " +
                             std::to_string(before) + " to " +
                             std::to_string(photonsOf(v, i, count)) + " texels (photon buffer " +
                             budgetText + "); texel footprint up to " + fixed2(footprint) +
                             " v0 (rule: " + fixed2(kTexelFootprintVoxels) + ")");
    }
    uint64_t total = photonsOf(v, 0, uint32_t(v.size()));
    if (limits.singleBatch && total > budget) {
        const uint64_t before = total;
        shrinkToFit(v, 0, uint32_t(v.size()), budget);
        total = photonsOf(v, 0, uint32_t(v.size()));
        double footprint = 0.0;
        for (const GpuLightView& view : v)
            footprint = std::max(footprint, texelFootprintVoxels(view, grid));
        plan.notes.push_back("light_map_resolution: all maps shrunk from " +
                             std::to_string(before) + " to " + std::to_string(total) +
                             " texels to fit one photon buffer (" + budgetText +
                             ", octree storage); texel footprint up to " + fixed2(footprint) +
                             " v0 (rule: " + fixed2(kTexelFootprintVoxels) + ")");
    }
    plan.photonCount = total;

    // Batches of whole lights
    uint64_t batchBudget =
        limits.singleBatch ? budget : std::min(budget, limits.batchBytes / sizeof(GpuPhoton));
    for (uint32_t i = 0; i < v.size(); i += v[i].group.z)
        batchBudget = std::max(batchBudget, photonsOf(v, i, v[i].group.z));
    for (uint32_t i = 0; i < v.size(); i += v[i].group.z) {
        const uint32_t count = v[i].group.z;
        const uint64_t photons = photonsOf(v, i, count);
        if (plan.batches.empty() || plan.batches.back().photons + photons > batchBudget) {
            LightViewBatch b;
            b.firstView = i;
            b.firstLight = v[i].group.x;
            plan.batches.push_back(b);
        }
        LightViewBatch& b = plan.batches.back();
        for (uint32_t j = i; j < i + count; ++j) {
            GpuLightView& view = v[j];
            view.texels.z = uint32_t(b.photons);
            view.texels.w = b.viewCount;
            view.group.w = uint32_t(plan.batches.size() - 1);
            b.photons += texelCount(view);
            ++b.viewCount;
            b.maxWidth = std::max(b.maxWidth, view.texels.x);
            b.maxHeight = std::max(b.maxHeight, view.texels.y);
        }
        ++b.lightCount;
    }
    for (const LightViewBatch& b : plan.batches) {
        plan.maxWidth = std::max(plan.maxWidth, b.maxWidth);
        plan.maxHeight = std::max(plan.maxHeight, b.maxHeight);
        plan.maxLayers = std::max(plan.maxLayers, b.viewCount);
        plan.maxBatchPhotons = std::max(plan.maxBatchPhotons, b.photons);
    }
    return plan;
}

LightInjection::LightInjection(TechniqueContext& ctx, const VoxelGrid& grid, uint32_t mapResolution,
                               bool singleBatch)
    : m_vk(ctx.vk), m_scene(ctx.gpuScene), m_grid(grid), m_mapResolution(mapResolution) {
    if (mapResolution != 0 && (mapResolution < 8 || mapResolution > 4096)) {
        throw Error("vct: light_map_resolution = " + std::to_string(mapResolution) +
                    " outside [8, 4096] (or 0 = from the texel footprint)");
    }
    const VkPhysicalDeviceLimits& deviceLimits = ctx.vk.properties().limits;
    m_limits.photonBufferBytes =
        std::min<uint64_t>(deviceLimits.maxStorageBufferRange, uint64_t(128) << 20);
    m_limits.maxImageDimension = deviceLimits.maxImageDimension2D;
    m_limits.singleBatch = singleBatch;
    m_plan = makePlan(ctx);
    for (const std::string& note : m_plan.notes)
        ctx.note(note);
    if (m_plan.batches.size() > 1) {
        ctx.note("light injection in " + std::to_string(m_plan.batches.size()) +
                 " batches of whole lights (" + std::to_string(m_plan.photonCount) +
                 " photons, <= " + std::to_string(m_plan.maxBatchPhotons) + " per batch)");
    }
    m_floatAtomics = ctx.vk.hasFloatAtomics();
    computeScales();
    allocatePhotons(ctx, m_plan.maxBatchPhotons);
    allocateViews(ctx, m_plan.views.size());
    m_viewBuffer.uploadVector(m_plan.views);
    allocateMaps(ctx, m_plan.maxWidth, m_plan.maxHeight, m_plan.maxLayers);

    m_rasterLayout = vk::PipelineLayout(ctx.vk, {m_scene.layout().handle()}, sizeof(LightViewPush));
    vk::GraphicsPipelineDesc desc;
    desc.vertexShader = "vct/light_view.vert";
    desc.fragmentShader = "vct/light_view.frag";
    desc.sceneVertexInput = false;
    desc.colorFormats = {kPositionFormat, kNormalFormat};
    desc.depthFormat = kDepthFormat;
    desc.depthCompare = VK_COMPARE_OP_GREATER;  // reversed Z
    desc.cull = VK_CULL_MODE_NONE;
    desc.name = ctx.tag("light_view");
    m_raster = vk::GraphicsPipeline(ctx.vk, desc, m_rasterLayout);

    const VkShaderStageFlags cs = VK_SHADER_STAGE_COMPUTE_BIT;
    m_photonSetLayout = vk::DescriptorSetLayout(ctx.vk,
                                                {{0, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE, 1, cs},
                                                 {1, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE, 1, cs},
                                                 {2, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, cs},
                                                 {3, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, cs}},
                                                ctx.tag("photons"));
    m_photonSet = vk::DescriptorSet(ctx.vk, m_photonSetLayout, 0, ctx.tag("photons"));
    writePhotonSet();
    m_photonLayout = vk::PipelineLayout(ctx.vk, {m_photonSetLayout.handle()}, sizeof(glm::uvec4));
    m_photonPipeline = vk::ComputePipeline(ctx.vk, "vct/photon_generate.comp", m_photonLayout);
}

LightViewPlan LightInjection::makePlan(TechniqueContext& ctx) const {
    return planLightViews(buildLightViews(ctx.scene, m_grid, ctx.shared.shadows().emitterSamples()),
                          m_grid, m_mapResolution, m_limits);
}

void LightInjection::computeScales() {
    // Fixed-point scales: the whole flux of every light fits in 2^31 units, and so does the sum
    // over lights of each light's largest photon irradiance (photons closer than v0 / 2 to a
    // light are clamped to it), so no voxel overflows
    double fluxBound = 0.0, irradianceBound = 0.0;
    m_irradianceCap.assign(m_plan.lightCount, 0.0f);
    const double rCap = 0.5 * double(m_grid.voxelSize());
    for (const GpuLightView& v : m_plan.views) {
        const glm::dvec3 f = lightViewFluxBound(v);
        fluxBound += std::max({f.x, f.y, f.z});
        const double i = std::max({v.intensity.x, v.intensity.y, v.intensity.z});
        const double cap = isOrtho(v) ? i : i / (rCap * rCap);
        m_irradianceCap[v.group.x] = float(std::max(double(m_irradianceCap[v.group.x]), cap));
    }
    for (float cap : m_irradianceCap)
        irradianceBound += double(cap);
    m_fixedScale = fluxBound > 0.0 ? 2.0e9 / fluxBound : 1.0;
    m_fixedIrradianceScale = irradianceBound > 0.0 ? 2.0e9 / irradianceBound : 1.0;
}

void LightInjection::allocatePhotons(TechniqueContext& ctx, uint64_t photons) {
    const VkBufferUsageFlags storage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT |
                                       VK_BUFFER_USAGE_TRANSFER_SRC_BIT |
                                       VK_BUFFER_USAGE_TRANSFER_DST_BIT;
    m_photonCapacity = std::max<uint64_t>(photons, 1);
    m_photons = vk::Buffer(ctx.vk, m_photonCapacity * sizeof(GpuPhoton), storage,
                           vk::MemoryUsage::DeviceLocal, ctx.tag("photons"));
}

void LightInjection::allocateViews(TechniqueContext& ctx, size_t views) {
    m_viewCapacity = std::max<size_t>(views, 1);
    m_viewBuffer = vk::Buffer(ctx.vk, m_viewCapacity * sizeof(GpuLightView),
                              VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, vk::MemoryUsage::DeviceLocal,
                              ctx.tag("light_views"));
}

void LightInjection::allocateMaps(TechniqueContext& ctx, uint32_t width, uint32_t height,
                                  uint32_t layers) {
    vk::ImageDesc map;
    map.kind = vk::ImageKind::Image2DArray;
    map.width = std::max(width, 1u);
    map.height = std::max(height, 1u);
    map.layers = std::max(layers, 1u);
    map.usage = VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_STORAGE_BIT;
    map.format = kPositionFormat;
    map.name = ctx.tag("light_view_positions");
    m_positionMap = vk::Image(ctx.vk, map);
    map.format = kNormalFormat;
    map.name = ctx.tag("light_view_normals");
    m_normalMap = vk::Image(ctx.vk, map);
    vk::ImageDesc depth;
    depth.format = kDepthFormat;
    depth.width = map.width;
    depth.height = map.height;
    depth.usage = VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT;
    depth.name = ctx.tag("light_view_depth");
    m_depth = vk::Image(ctx.vk, depth);
}

void LightInjection::writePhotonSet() {
    m_photonSet.writeStorageImage(0, m_positionMap.view());
    m_photonSet.writeStorageImage(1, m_normalMap.view());
    m_photonSet.writeBuffer(2, m_viewBuffer);
    m_photonSet.writeBuffer(3, m_photons);
}

bool LightInjection::refresh(TechniqueContext& ctx) {
    LightViewPlan plan = makePlan(ctx);
    if (plan.views.size() != m_plan.views.size() || plan.lightCount != m_plan.lightCount)
        throw Error("vct: the light views changed in number (a light changed type?)");
    m_plan = std::move(plan);
    m_recordedBatch = 0;
    computeScales();
    // Grow (never shrink) what the new plan does not fit; the rest is reused as it is
    bool grown = false;
    if (m_plan.maxBatchPhotons > m_photonCapacity) {
        allocatePhotons(ctx, m_plan.maxBatchPhotons);
        grown = true;
    }
    if (m_plan.views.size() > m_viewCapacity) {
        allocateViews(ctx, m_plan.views.size());
        grown = true;
    }
    const vk::ImageDesc& current = m_positionMap.desc();
    if (m_plan.maxWidth > current.width || m_plan.maxHeight > current.height ||
        m_plan.maxLayers > current.layers) {
        allocateMaps(ctx, std::max(m_plan.maxWidth, current.width),
                     std::max(m_plan.maxHeight, current.height),
                     std::max(m_plan.maxLayers, current.layers));
        grown = true;
    }
    m_viewBuffer.uploadVector(m_plan.views);
    if (grown) writePhotonSet();
    return grown;
}

PhotonSource LightInjection::photons() const {
    const uint64_t count = m_plan.batches.empty() ? 0 : m_plan.batches[m_recordedBatch].photons;
    return {&m_photons, uint32_t(count)};
}

std::string LightInjection::mapSummary() const {
    if (m_plan.views.empty()) return "none";
    glm::uvec2 lo(~0u), hi(0u);
    uint64_t loArea = ~uint64_t(0), hiArea = 0;
    for (const GpuLightView& v : m_plan.views) {
        const uint64_t area = texelCount(v);
        if (area < loArea) loArea = area, lo = glm::uvec2(v.texels);
        if (area > hiArea) hiArea = area, hi = glm::uvec2(v.texels);
    }
    auto size = [](glm::uvec2 s) { return std::to_string(s.x) + "x" + std::to_string(s.y); };
    std::string text = lo == hi ? size(hi) : size(lo) + ".." + size(hi);
    text += " x " + std::to_string(m_plan.views.size()) +
            (m_plan.views.size() == 1 ? " view" : " views");
    if (m_plan.batches.size() > 1)
        text += " (" + std::to_string(m_plan.batches.size()) + " batches)";
    return text;
}

void LightInjection::recordLightViews(TechniqueContext& ctx, VkCommandBuffer cmd, uint32_t batch,
                                      bool timed) {
    const LightViewBatch& b = m_plan.batches[batch];
    {
        std::optional<PassScope> pass;
        if (timed) pass.emplace(ctx, cmd, "inject.light_view");
        m_positionMap.transition(cmd, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL);
        m_normalMap.transition(cmd, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL);
        m_raster.bind(cmd);
        VkDescriptorSet set = m_scene.set().handle();
        vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, m_rasterLayout.handle(), 0, 1,
                                &set, 0, nullptr);
        for (uint32_t i = b.firstView; i < b.firstView + b.viewCount; ++i) {
            const GpuLightView& v = m_plan.views[i];
            m_depth.transition(cmd, VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL);
            const VkClearColorValue zero{{0.0f, 0.0f, 0.0f, 0.0f}};
            vk::ColorTarget position{m_positionMap.layerView(v.texels.w, 0), zero,
                                     VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL};
            vk::ColorTarget normal{m_normalMap.layerView(v.texels.w, 0), zero,
                                   VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL};
            vk::DepthTarget depth;
            depth.view = m_depth.view();
            depth.clear = 0.0f;  // reversed Z
            depth.store = false;
            vk::RenderingScope scope(cmd, {v.texels.x, v.texels.y}, {position, normal}, depth);
            LightViewPush push;
            push.viewProj = v.viewProj;
            push.toLight = isOrtho(v) ? glm::vec4(-glm::normalize(glm::vec3(v.forward)), 1.0f)
                                      : glm::vec4(glm::vec3(v.positionKind), 0.0f);
            push.skipPlane = v.skipPlane;
            push.skip = glm::vec4(v.cone.w, 0.0f, 0.0f, 0.0f);
            m_rasterLayout.push(cmd, push);
            if (m_scene.triangleCount() > 0) vkCmdDraw(cmd, 3 * m_scene.triangleCount(), 1, 0, 0);
        }
        m_positionMap.transition(cmd, VK_IMAGE_LAYOUT_GENERAL);
        m_normalMap.transition(cmd, VK_IMAGE_LAYOUT_GENERAL);
    }
    {
        std::optional<PassScope> pass;
        if (timed) pass.emplace(ctx, cmd, "inject.photons");
        vk::memoryBarrier(cmd);
        m_photonPipeline.bind(cmd);
        VkDescriptorSet set = m_photonSet.handle();
        vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, m_photonLayout.handle(), 0, 1,
                                &set, 0, nullptr);
        m_photonLayout.push(cmd, glm::uvec4(b.firstView, b.viewCount, 0u, 0u));
        vkCmdDispatch(cmd, (b.maxWidth + 7) / 8, (b.maxHeight + 7) / 8, b.viewCount);
        vk::memoryBarrier(cmd);
    }
    m_recordedBatch = batch;
}

void LightInjection::recordPhotons(TechniqueContext& ctx, VkCommandBuffer cmd) {
    if (m_plan.batches.empty()) return;
    recordLightViews(ctx, cmd, 0, true);
}

void LightInjection::ensureDenseResources(TechniqueContext& ctx) {
    if (!m_flux.empty()) return;
    const VkDeviceSize planeBytes = VkDeviceSize(m_grid.voxelCount()) * 4;
    if (planeBytes > ctx.vk.properties().limits.maxStorageBufferRange) {
        throw DeviceLimitError("vct: voxel_resolution = " + std::to_string(m_grid.resolution()) +
                               " needs a flux plane above the device's maxStorageBufferRange");
    }
    const VkBufferUsageFlags usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT |
                                     VK_BUFFER_USAGE_TRANSFER_DST_BIT |
                                     VK_BUFFER_USAGE_TRANSFER_SRC_BIT;
    static const char* kFlux[3] = {"flux.r", "flux.g", "flux.b"};
    static const char* kIrradiance[3] = {"irradiance.r", "irradiance.g", "irradiance.b"};
    for (int k = 0; k < 3; ++k) {
        m_flux.emplace_back(ctx.vk, planeBytes, usage, vk::MemoryUsage::DeviceLocal,
                            ctx.tag(kFlux[k]));
        m_irradiance.emplace_back(ctx.vk, planeBytes, usage, vk::MemoryUsage::DeviceLocal,
                                  ctx.tag(kIrradiance[k]));
    }
    m_count = vk::Buffer(ctx.vk, planeBytes, usage, vk::MemoryUsage::DeviceLocal,
                         ctx.tag("photon_count"));
    if (m_splatLayout.handle() != VK_NULL_HANDLE) return;
    vk::SamplerDesc s;
    s.filter = VK_FILTER_NEAREST;
    s.mipmap = VK_SAMPLER_MIPMAP_MODE_NEAREST;
    s.name = ctx.tag("nearest");
    m_nearest = vk::Sampler(ctx.vk, s);
    const VkShaderStageFlags cs = VK_SHADER_STAGE_COMPUTE_BIT;
    m_splatSetLayout =
        vk::DescriptorSetLayout(ctx.vk,
                                {{0, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, cs},
                                 {1, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, 1, cs},
                                 {2, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 3, cs},
                                 {3, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE, 1, cs},
                                 {4, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 3, cs},
                                 {5, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, cs},
                                 {6, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, cs}},
                                ctx.tag("splat"));
    m_splatLayout = vk::PipelineLayout(ctx.vk, {m_splatSetLayout.handle()}, sizeof(InjectPush));
    m_splat = vk::ComputePipeline(
        ctx.vk, m_floatAtomics ? "vct/splat_dense.comp" : "vct/splat_dense_fixed.comp",
        m_splatLayout);
    m_shade16 = vk::ComputePipeline(
        ctx.vk, m_floatAtomics ? "vct/inject_shade.comp" : "vct/inject_shade_fixed.comp",
        m_splatLayout);
    m_shade32 = vk::ComputePipeline(
        ctx.vk, m_floatAtomics ? "vct/inject_shade_f32.comp" : "vct/inject_shade_fixed_f32.comp",
        m_splatLayout);
}

void LightInjection::recordBatchSplat(TechniqueContext& ctx, VkCommandBuffer cmd, uint32_t batch,
                                      bool timed) {
    const LightViewBatch& b = m_plan.batches[batch];
    std::optional<PassScope> pass;
    if (timed) pass.emplace(ctx, cmd, "inject.splat");
    m_splat.bind(cmd);
    VkDescriptorSet set = m_splatSet.handle();
    vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, m_splatLayout.handle(), 0, 1, &set,
                            0, nullptr);
    InjectPush push;
    push.grid = m_grid.gpu();
    push.scale = glm::vec4(float(m_fixedScale), float(1.0 / m_fixedScale),
                           float(m_fixedIrradianceScale), float(1.0 / m_fixedIrradianceScale));
    // One light at a time: its deposit count per voxel, then its mean irradiance
    for (uint32_t i = b.firstView; i < b.firstView + b.viewCount; i += m_plan.views[i].group.z) {
        const GpuLightView& first = m_plan.views[i];
        const uint32_t views = first.group.z;
        const uint64_t photons = photonsOf(m_plan.views, i, views);
        vkCmdFillBuffer(cmd, m_count.handle(), 0, VK_WHOLE_SIZE, 0);
        vk::memoryBarrier(cmd);
        push.counts = glm::uvec4(uint32_t(photons), first.texels.z, kModeCount, 0u);
        push.light = glm::uvec4(i, views, 0u, 0u);
        push.params = glm::vec4(m_irradianceCap[first.group.x], 0.0f, 0.0f, 0.0f);
        m_splatLayout.push(cmd, push);
        vk::dispatch1D(cmd, uint32_t(photons), 64);
        vk::memoryBarrier(cmd);
        push.counts.z = kModeIrradiance;
        m_splatLayout.push(cmd, push);
        vk::dispatch1D(cmd, uint32_t(photons), 64);
        vk::memoryBarrier(cmd);
    }
}

void LightInjection::recordSplat(TechniqueContext& ctx, VkCommandBuffer cmd,
                                 vk::Image& albedoOpacity) {
    ensureDenseResources(ctx);
    m_splatSet = vk::DescriptorSet(ctx.vk, m_splatSetLayout, 0, ctx.tag("splat"));
    m_splatSet.writeBuffer(0, m_photons);
    m_splatSet.writeSampledImage(1, albedoOpacity.view(), m_nearest.handle(),
                                 VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL);
    for (uint32_t k = 0; k < 3; ++k) {
        m_splatSet.writeBuffer(2, m_flux[k], k);
        m_splatSet.writeBuffer(4, m_irradiance[k], k);
    }
    m_splatSet.writeBuffer(5, m_count);
    m_splatSet.writeBuffer(6, m_viewBuffer);

    {
        PassScope pass(ctx, cmd, "inject.splat");
        for (const vk::Buffer& plane : m_flux)
            vkCmdFillBuffer(cmd, plane.handle(), 0, VK_WHOLE_SIZE, 0);
        for (const vk::Buffer& plane : m_irradiance)
            vkCmdFillBuffer(cmd, plane.handle(), 0, VK_WHOLE_SIZE, 0);
        vk::memoryBarrier(cmd);
    }
    if (m_plan.batches.empty()) return;
    recordBatchSplat(ctx, cmd, 0, true);
    const uint32_t batches = uint32_t(m_plan.batches.size());
    if (batches == 1) return;
    // Further batches: light views, photons and splat of each (the timer's per-step scopes are
    // summed by name; past kMaxTimedBatches batches they are timed together instead)
    const bool timed = batches <= kMaxTimedBatches;
    std::optional<PassScope> together;
    if (!timed) together.emplace(ctx, cmd, "inject.batches");
    for (uint32_t b = 1; b < batches; ++b) {
        recordLightViews(ctx, cmd, b, timed);
        recordBatchSplat(ctx, cmd, b, timed);
    }
}

void LightInjection::recordShade(TechniqueContext& ctx, VkCommandBuffer cmd,
                                 vk::Image& albedoOpacity, vk::Image& target) {
    ensureDenseResources(ctx);
    const bool f32 = target.format() == VK_FORMAT_R32G32B32A32_SFLOAT;
    if (!f32 && target.format() != VK_FORMAT_R16G16B16A16_SFLOAT) {
        throw Error("vct: radiance volume must be RGBA16F or RGBA32F");
    }
    m_shadeSet = vk::DescriptorSet(ctx.vk, m_splatSetLayout, 0, ctx.tag("shade"));
    m_shadeSet.writeSampledImage(1, albedoOpacity.view(), m_nearest.handle(),
                                 VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL);
    for (uint32_t k = 0; k < 3; ++k)
        m_shadeSet.writeBuffer(4, m_irradiance[k], k);
    m_shadeSet.writeStorageImage(3, target.view());

    PassScope pass(ctx, cmd, "inject.shade");
    target.transition(cmd, VK_IMAGE_LAYOUT_GENERAL);
    (f32 ? m_shade32 : m_shade16).bind(cmd);
    VkDescriptorSet set = m_shadeSet.handle();
    vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, m_splatLayout.handle(), 0, 1, &set,
                            0, nullptr);
    InjectPush push;
    push.grid = m_grid.gpu();
    push.scale = glm::vec4(float(m_fixedScale), float(1.0 / m_fixedScale),
                           float(m_fixedIrradianceScale), float(1.0 / m_fixedIrradianceScale));
    m_splatLayout.push(cmd, push);
    const uint32_t groups = (m_grid.resolution() + 3) / 4;
    vkCmdDispatch(cmd, groups, groups, groups);
    vk::memoryBarrier(cmd);
}

std::vector<GpuPhoton> LightInjection::readPhotons() {
    return m_photons.downloadVector<GpuPhoton>(photons().count);
}

std::vector<glm::vec3> LightInjection::readPlanes(std::vector<vk::Buffer>& planes,
                                                  double unitsPer) {
    if (planes.empty()) throw Error("vct: injection accumulators were released or never made");
    const size_t n = m_grid.voxelCount();
    std::vector<glm::vec3> out(n, glm::vec3(0.0f));
    for (int k = 0; k < 3; ++k) {
        if (m_floatAtomics) {
            const std::vector<float> v = planes[size_t(k)].downloadVector<float>(n);
            for (size_t i = 0; i < n; ++i)
                out[i][k] = v[i];
        } else {
            const std::vector<uint32_t> v = planes[size_t(k)].downloadVector<uint32_t>(n);
            for (size_t i = 0; i < n; ++i)
                out[i][k] = float(double(v[i]) / unitsPer);
        }
    }
    return out;
}

std::vector<glm::vec3> LightInjection::readVoxelFlux() {
    return readPlanes(m_flux, m_fixedScale);
}

std::vector<glm::vec3> LightInjection::readVoxelIrradiance() {
    return readPlanes(m_irradiance, m_fixedIrradianceScale);
}

size_t LightInjection::memoryBytes() const {
    size_t bytes = size_t(m_photons.size()) + size_t(m_viewBuffer.size());
    const vk::ImageDesc& map = m_positionMap.desc();
    const size_t texels = size_t(std::max(map.width, 1u)) * std::max(map.height, 1u);
    bytes += texels * (16 + 8) * std::max<size_t>(map.layers, 1) + texels * 4;
    for (const vk::Buffer& b : m_flux)
        bytes += size_t(b.size());
    for (const vk::Buffer& b : m_irradiance)
        bytes += size_t(b.size());
    if (m_count.valid()) bytes += size_t(m_count.size());
    return bytes;
}

}  // namespace gilab::vct
