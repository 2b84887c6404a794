#include "vct.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <string>

#include <glm/glm.hpp>

#include "core/gpu/gpu_scene.h"
#include "core/passes/shared_passes.h"
#include "core/scene/animation.h"
#include "core/scene/scene.h"
#include "core/technique/registry.h"
#include "core/util/error.h"
#include "core/vk/barrier.h"
#include "core/vk/context.h"
#include "core/voxel/cone_set.h"
#include "core/voxel/voxel_debug_view.h"
#include "core/voxel/voxel_radiance.h"
#include "core/voxel/voxelizer.h"
#include "light_injection.h"
#include "svo.h"

namespace gilab {
namespace {

constexpr uint32_t kFlagSpecular = 1u, kFlagAo = 2u, kFlagAnisotropic = 4u, kFlagLevel0Rays = 8u;
constexpr uint32_t kParamsBinding = 6;

/** Mirrors GatherParams in techniques/vct/shaders/gather_inputs.glsl (std140, all vec4). */
struct GpuGatherParams {
    glm::vec4 gridMinV0;
    glm::vec4 gridMaxStep;
    glm::vec4 distances;
    glm::vec4 misc;
    GpuConeSet coneSet;
    glm::vec4 cameraPosition;
    glm::uvec4 sizeFlags;
    glm::vec4 specular;
    GpuVoxelGrid grid;
};
static_assert(sizeof(GpuGatherParams) == 4 * 16 + sizeof(GpuConeSet) + 3 * 16 + 32);

std::string mib(size_t bytes) {
    char text[32];
    std::snprintf(text, sizeof(text), "%.2f MiB", double(bytes) / (1024.0 * 1024.0));
    return text;
}

/** Bytes of one mip-less 3D volume. */
size_t volumeBytes(const vk::Image& image) {
    const vk::ImageDesc& d = image.desc();
    return size_t(d.width) * d.height * d.depth * vk::formatBytesPerTexel(d.format);
}

std::vector<vk::DescriptorBinding> toBindings(const std::vector<VkDescriptorSetLayoutBinding>& in) {
    std::vector<vk::DescriptorBinding> out;
    for (const VkDescriptorSetLayoutBinding& b : in)
        out.push_back({b.binding, b.descriptorType, b.descriptorCount, b.stageFlags});
    return out;
}

}  // namespace

VctTechnique::VctTechnique() = default;
VctTechnique::~VctTechnique() = default;

TechniqueInfo VctTechnique::describe() {
    TechniqueInfo info;
    info.id = "vct";
    info.description =
        "Voxel cone tracing: photon injection from light-view maps into a voxel radiance "
        "pyramid (dense or sparse octree), diffuse + specular cones per pixel; one bounce";
    info.citation =
        "C. Crassin, F. Neyret, M. Sainz, S. Green, E. Eisemann, \"Interactive Indirect "
        "Illumination Using Voxel Cone Tracing\", Computer Graphics Forum 30(7), 2011";
    info.indirectBounces = 1;
    info.supports.pointLights = true;
    info.supports.spotLights = true;
    info.supports.directionalLights = true;
    info.supports.emissiveSurfaces = true;  // emitter samples injected through hemicube maps
    const ParamStage rebuild = ParamStage::Rebuild;
    info.params = {
        requirePowerOfTwo(intParam(
            "voxel_resolution", 128, 32, 512, "voxels",
            "voxels per grid axis (paper: 512^3 = 9 octree levels; 128 fits lavapipe); a power "
            "of two (mip pyramid / octree levels)",
            rebuild)),
        enumParam("storage", "dense", {"dense", "octree"},
                  "radiance storage: dense 3D textures with mips, or the paper's sparse voxel "
                  "octree with 3^3 bricks",
                  rebuild),
        enumParam("octree_filter", "slab", {"pairs", "slab"},
                  "octree directional bricks: pairs = the dense rule (front-to-back child pairs "
                  "in the Gaussian, Crassin §9); slab = front to back through the parent's whole "
                  "footprint (walls on odd samples stay opaque; techniques/vct/svo.md)",
                  rebuild),
        boolParam("anisotropic", true,
                  "6 directional mip volumes (dense) or directional bricks above the leaves "
                  "(octree) (Crassin §9); off = isotropic mips with the 3^3 Gaussian filter",
                  rebuild),
        allowValue(0, intParam("light_map_resolution", 0, 8, 4096, "texels",
                               "light-view map side per light view (0 = auto: texel footprint <= "
                               "v0/2 on the farthest grid corner, the paper's rule; clamped to "
                               "the device limits)",
                               rebuild)),
        intParam("diffuse_cones", 6, 1, 16, "",
                 "diffuse cones: one along the normal + a ring (paper timings: 3)"),
        floatParam("diffuse_aperture_deg", 60.0, 1.0, 179.0, "deg",
                   "full apex angle of each diffuse cone"),
        floatParam("diffuse_tilt_deg", 60.0, 0.0, 89.0, "deg",
                   "angle of the ring cones from the normal"),
        floatParam("step_factor", 0.5, 0.05, 2.0, "",
                   "cone step d' = step_factor x cone diameter (the paper does not fix it; "
                   "techniques/vct/README.md)"),
        floatParam("max_distance", 1.0, 0.01, 2.0, "grid sides",
                   "maximum cone length in units of the voxel grid's side"),
        floatParam("origin_offset", 1.5, 0.0, 8.0, "voxels",
                   "cone origin offset along the surface normal, in finest voxels"),
        floatParam("lod_offset", 0.0, -2.0, 8.0, "levels",
                   "added to the cone's level log2(radius / v0) (Crassin §5: the level of the "
                   "cone radius); -1 = the node-size reading (needs step_factor <= 0.125)"),
        floatParam("lift", 1.5, 0.0, 4.0, "cells",
                   "keep each sample >= lift x v0 x 2^ceil(L) above the surface plane so the "
                   "surface's own cell is never gathered (0 = off; the octree adds "
                   "octree_lift_extra; docs/voxel_cone_tracing.md)"),
        floatParam("octree_lift_extra", 0.25, 0.0, 1.0, "cells",
                   "added to lift with storage = octree (vertex-centred samples reach further "
                   "than cells): 0.5 = worst-case clearance (no self-gather, +24-38 % energy "
                   "over dense), 0.25 = matches dense; techniques/vct/svo.md \"Lift\""),
        enumParam("lift_rule", "cell", {"cell", "blend"},
                  "cell: clear the coarser blended level's cell 2^ceil(L) (exact, no self-gather); "
                  "blend: the two cell sizes mixed by the level weight (continuous in t)"),
        floatParam("opacity_cutoff", 0.99, 0.5, 1.0, "",
                   "a cone stops when its accumulated opacity reaches this"),
        boolParam("specular", true,
                  "one specular cone along the mirrored view direction on glossy pixels"),
        floatParam("specular_min_aperture_deg", 10.0, 0.1, 60.0, "deg",
                   "narrowest specular cone (paper: 10 deg, Table 1; the roughness mapping is "
                   "clamped to [this, 60])"),
        intParam("control_level0_rays", 0, 0, 4096, "rays",
                 "a control, not the method (issue 43): > 0 replaces the diffuse cones by that "
                 "many cosine-distributed rays per pixel marched through the finest voxels only "
                 "(no mips: the cone march at aperture 0), so the injected volume's light is "
                 "gathered without cone tracing's filtering; 0 = the cones"),
        boolParam("power_stats", false,
                  "a diagnostic (issue 43; dense storage): after set-up, read back the volumes "
                  "and report the power the photons brought (sum of albedo x flux per voxel) and "
                  "the power the base volume holds (sum of pi L x the mean plane area in a voxel "
                  "of its normal, v0^2 / |n|_1); read outside the timed frame"),
        boolParam("ao", false, "trace AO cones (debug view \"ao\"; not applied to the image)",
                  rebuild),
        floatParam("ao_falloff", 1.0, 0.0, 1000.0, "1/m",
                   "AO distance falloff lambda in f(r) = 1 / (1 + lambda r) (Crassin §6)"),
    };
    return info;
}

void VctTechnique::setup(TechniqueContext& ctx) {
    const ParamSet& p = ctx.params;
    const uint32_t n = uint32_t(p.getInt("voxel_resolution"));
    int mapRes = p.getInt("light_map_resolution");
    m_octree = p.getEnum("storage") == "octree";
    m_ao = p.getBool("ao");
    m_powerStatsDue = p.getBool("power_stats");
    if (!ctx.scene.caps.bounds.valid()) throw Error("vct: the scene has no geometry");

    // Release the previous set-up's resources first (rebuild)
    m_gather = {};
    m_voxelView.reset();
    m_svo.reset();
    m_radiance.reset();
    m_injection.reset();
    m_voxelizer.reset();

    m_grid = VoxelGrid(ctx.scene.caps.bounds, n);
    m_voxelizer = std::make_unique<Voxelizer>(ctx.vk, ctx.gpuScene, m_grid);
    m_injection = std::make_unique<vct::LightInjection>(ctx, m_grid, uint32_t(mapRes), m_octree);
    ctx.note("voxel grid " + std::to_string(n) + "^3, v0 = " + std::to_string(m_grid.voxelSize()) +
             " m (paper: 512^3, 9 levels); light-view maps " + m_injection->mapSummary() + " = " +
             std::to_string(m_injection->photonCount()) + " photons");
    ctx.note(
        "light is injected at set-up and re-injected (inject + filter, voxelization kept) when "
        "a light changes, as the paper does when the light moves");
    if (m_injection->viewCount() == 0) ctx.skip("inject", "no lights and no emitter samples");

    if (!m_octree) {
        VoxelRadianceOptions options;
        options.anisotropic = p.getBool("anisotropic");
        options.isotropicFilter = VoxelMipFilter::Gaussian;
        m_radiance = std::make_unique<VoxelRadiance>(ctx.vk, m_grid, options, ctx.tag("radiance"));
        // Shade voxels toward the cone through their averaged normal (Crassin §7): no back glow
        m_radiance->setSurfaceNormals(m_voxelizer->volumes().normal);
        ctx.submitTimed([&](VkCommandBuffer cmd) {
            m_voxelizer->record(cmd, ctx.timer);
            recordInjection(ctx, cmd);
        });
        m_voxelizer->releaseAccumulators();
        ctx.note("dense radiance (" +
                 std::string(options.anisotropic ? "anisotropic" : "isotropic") +
                 "): " + mib(m_radiance->memoryBytes()) + "; injection scratch " +
                 mib(m_injection->memoryBytes()) +
                 ", kept for re-injection when a light changes, as are the voxelizer's "
                 "albedo/opacity and normal volumes (" +
                 mib(volumeBytes(m_voxelizer->volumes().albedoOpacity) +
                     volumeBytes(m_voxelizer->volumes().normal)) +
                 ")");
        ctx.note(
            "voxels store outgoing diffuse radiance (a albedo/pi E), not the paper's incoming "
            "lobe: same result for Lambertian voxels, glossy secondary bounces are lost");
        // The voxel debug view: rendered once (static camera and geometry)
        m_voxelView = std::make_unique<VoxelDebugView>(ctx.vk, *m_voxelizer, ctx.width, ctx.height);
        ctx.submitTimed([&](VkCommandBuffer cmd) {
            m_voxelView->record(cmd, ctx.scene.camera, VoxelDebugMode::Albedo);
        });
    } else {
        const bool anisotropic = p.getBool("anisotropic");
        const auto filter = p.getEnum("octree_filter") == "slab"
                                ? vct::SparseVoxelOctree::DirectionalFilter::Slab
                                : vct::SparseVoxelOctree::DirectionalFilter::Pairs;
        m_svo = std::make_unique<vct::SparseVoxelOctree>(ctx, m_grid, anisotropic, filter);
        ctx.submitTimed([&](VkCommandBuffer cmd) {
            m_voxelizer->record(cmd, ctx.timer);
            {
                PassScope pass(ctx, cmd, "svo_build");
                m_svo->build(ctx, cmd, m_voxelizer->volumes());
            }
            recordInjection(ctx, cmd);
        });
        // The octree holds everything the trace and a re-injection need (geometry and normal
        // bricks, irradiance accumulators): the dense volumes go
        m_voxelizer.reset();
        const vct::SparseVoxelOctree::Memory mem = m_svo->memory();
        const size_t dense = VoxelRadiance::memoryBytesFor(n, VoxelRadianceOptions{});
        ctx.note(std::string("octree (") + (anisotropic ? "anisotropic" : "isotropic") +
                 "): nodes " + mib(mem.nodeBytes) + " (" + std::to_string(mem.nodeCount) +
                 ") + bricks " + mib(mem.brickBytes) + " (geometry " +
                 std::to_string(mem.brickCount) + ", radiance " +
                 std::to_string(mem.radianceCount) + ") = " + mib(mem.total()) +
                 "; a dense anisotropic pyramid at this resolution would take " + mib(dense));
        ctx.note(
            "kept for re-injection when a light changes: the octree's scratch "
            "(irradiance accumulators, deposit counts, light ranges, occupancy) " +
            mib(mem.scratchBytes) + " and the photons and light-view maps " +
            mib(m_injection->memoryBytes()) + "; the dense voxel volumes are freed");
    }
    if (!ctx.scene.caps.hasGlossy) {
        ctx.skip("specular_cone", "scene has no glossy materials");
    } else if (!p.getBool("specular")) {
        ctx.skip("specular_cone", "specular = false");
    }
    if (!m_ao) ctx.skip("ao", "ao = false");
    createGather(ctx);
}

void VctTechnique::recordInjection(TechniqueContext& ctx, VkCommandBuffer cmd) {
    if (m_octree) {
        // Photons, then the octree's splat / transfer / shade / filter up (svo_* nested here)
        PassScope pass(ctx, cmd, "inject");
        m_injection->recordPhotons(ctx, cmd);
        m_svo->inject(ctx, cmd, m_injection->photons());
        return;
    }
    vk::Image& albedoOpacity = m_voxelizer->volumes().albedoOpacity;
    {
        PassScope pass(ctx, cmd, "inject");
        m_injection->recordPhotons(ctx, cmd);
        m_injection->recordSplat(ctx, cmd, albedoOpacity);  // clears the accumulators first
        m_injection->recordShade(ctx, cmd, albedoOpacity, m_radiance->base());  // every voxel
    }
    PassScope pass(ctx, cmd, "filter");
    m_radiance->filter(cmd);
}

UpdateKind VctTechnique::update(TechniqueContext& ctx, const SceneChanges& changes) {
    if (changes.geometry || !m_injection) return Technique::update(ctx, changes);
    // The cone trace reads the G-buffer and the camera every frame; only the debug view was
    // rendered with the set-up camera
    if (changes.camera && m_voxelView) m_voxelViewStale = true;
    if (changes.lights.empty()) return UpdateKind::None;
    // Light moved: the voxelization (static geometry) stays; re-plan the light views for the
    // new lights, then re-inject and re-filter (Crassin: re-injection on light motion)
    const bool grown = m_injection->refresh(ctx);
    if (grown)
        ctx.note("light-view maps / photon buffer grown for a moved light: injection scratch " +
                 mib(m_injection->memoryBytes()));
    if (m_svo) m_svo->updateLights(ctx);
    if (m_injection->viewCount() == 0) return UpdateKind::None;
    ctx.submitTimed([&](VkCommandBuffer cmd) { recordInjection(ctx, cmd); });
    return UpdateKind::Incremental;
}

void VctTechnique::createGather(TechniqueContext& ctx) {
    const VkShaderStageFlags cs = VK_SHADER_STAGE_COMPUTE_BIT;
    vk::ImageDesc desc;
    desc.format = VK_FORMAT_R32G32B32A32_SFLOAT;
    desc.width = ctx.width;
    desc.height = ctx.height;
    desc.usage = VK_IMAGE_USAGE_STORAGE_BIT | VK_IMAGE_USAGE_SAMPLED_BIT;
    desc.name = ctx.tag("ao");
    m_aoImage = vk::Image(ctx.vk, desc);
    ctx.vk.submitAndWait([&](VkCommandBuffer cmd) {
        m_aoImage.clearColor(cmd, VkClearColorValue{{0.0f, 0.0f, 0.0f, 0.0f}});
    });
    m_params = vk::Buffer(ctx.vk, sizeof(GpuGatherParams), VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT,
                          vk::MemoryUsage::Upload, ctx.tag("gather_params"));

    std::vector<vk::DescriptorBinding> inputs;
    for (uint32_t b = 0; b <= 5; ++b)
        inputs.push_back({b, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE, 1, cs});
    inputs.push_back({kParamsBinding, VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER, 1, cs});
    m_inputLayout = vk::DescriptorSetLayout(ctx.vk, inputs, ctx.tag("gather_inputs"));
    m_inputSet = {};

    std::vector<vk::DescriptorBinding> voxels;
    if (m_octree) {
        std::vector<VkDescriptorSetLayoutBinding> raw;
        vct::SparseVoxelOctree::addLayoutBindings(raw, 0, cs);
        voxels = toBindings(raw);
    } else {
        VoxelRadiance::addLayoutBindings(voxels, 0, cs);
    }
    m_voxelLayout = vk::DescriptorSetLayout(ctx.vk, voxels, ctx.tag("gather_voxels"));
    m_voxelSet = vk::DescriptorSet(ctx.vk, m_voxelLayout, 0, ctx.tag("gather_voxels"));
    if (m_octree) {
        m_svo->writeDescriptors(m_voxelSet, 0);
    } else {
        m_radiance->writeDescriptors(m_voxelSet, 0);
    }
    m_gatherLayout =
        vk::PipelineLayout(ctx.vk, {m_inputLayout.handle(), m_voxelLayout.handle()}, 0);
    m_gather = vk::ComputePipeline(
        ctx.vk, m_octree ? vct::SparseVoxelOctree::gatherShaderName() : "vct/gather_dense.comp",
        m_gatherLayout);
}

void VctTechnique::frameFinished(TechniqueContext& ctx) {
    if (!m_powerStatsDue) return;
    m_powerStatsDue = false;
    if (!m_radiance || !m_voxelizer || !m_injection) return;
    // Issue 43's control: what the photons brought against what the level-0 volume holds.
    const std::vector<glm::vec3> flux = m_injection->readVoxelFlux();
    uint32_t albedoChannels = 0, baseChannels = 0, normalChannels = 0;
    const std::vector<float> albedo =
        m_voxelizer->volumes().albedoOpacity.readbackFloat(ctx.vk, 0, 0, &albedoChannels);
    const std::vector<float> base = m_radiance->base().readbackFloat(ctx.vk, 0, 0, &baseChannels);
    const std::vector<float> normal =
        m_voxelizer->volumes().normal.readbackFloat(ctx.vk, 0, 0, &normalChannels);
    const size_t voxels = flux.size();
    if (albedo.size() < voxels * albedoChannels || base.size() < voxels * baseChannels ||
        normal.size() < voxels * normalChannels || albedoChannels < 3 || baseChannels < 3 ||
        normalChannels < 3)
        return;
    const double v0 = m_grid.voxelSize();
    double photons = 0.0, volume = 0.0;
    size_t lit = 0;
    for (size_t i = 0; i < voxels; ++i) {
        const float* a = &albedo[i * albedoChannels];
        photons +=
            (double(a[0]) * flux[i].x + double(a[1]) * flux[i].y + double(a[2]) * flux[i].z) / 3.0;
        const float* b = &base[i * baseChannels];
        const double l = (double(b[0]) + b[1] + b[2]) / 3.0;
        if (!(l > 0.0)) continue;
        ++lit;
        const float* nv = &normal[i * normalChannels];
        const glm::dvec3 m(nv[0], nv[1], nv[2]);
        const double len = glm::length(m);
        const double l1 = len > 0.1 ? (std::abs(m.x) + std::abs(m.y) + std::abs(m.z)) / len : 1.0;
        volume += std::numbers::pi * l * v0 * v0 / l1;
    }
    ctx.stat("power_photons_reflected_w", photons);
    ctx.stat("power_volume_w", volume);
    ctx.stat("power_volume_over_photons", photons > 0.0 ? volume / photons : 0.0);
    ctx.stat("lit_base_voxels", double(lit));
}

void VctTechnique::render(TechniqueContext& ctx, VkCommandBuffer cmd, FrameTargets& targets) {
    const ParamSet& p = ctx.params;
    GBuffer& gb = ctx.shared.gbuffer();
    // The frame images are stable for a harness; (re)write the inputs when the set is new
    if (m_inputSet.handle() == VK_NULL_HANDLE) {
        m_inputSet = vk::DescriptorSet(ctx.vk, m_inputLayout, 0, ctx.tag("gather_inputs"));
        m_inputSet.writeStorageImage(0, gb.position.view());
        m_inputSet.writeStorageImage(1, gb.normal.view());
        m_inputSet.writeStorageImage(2, gb.albedo.view());
        m_inputSet.writeStorageImage(3, gb.material.view());
        m_inputSet.writeStorageImage(4, targets.indirect.view());
        m_inputSet.writeStorageImage(5, m_aoImage.view());
        m_inputSet.writeUniformBuffer(kParamsBinding, m_params);
    }

    const float v0 = m_grid.voxelSize();
    const ConeSet cones =
        makeDiffuseConeSet(uint32_t(p.getInt("diffuse_cones")), p.getFloat("diffuse_aperture_deg"),
                           p.getFloat("diffuse_tilt_deg"));
    uint32_t flags = 0;
    if (p.getBool("specular") && ctx.scene.caps.hasGlossy) flags |= kFlagSpecular;
    if (m_ao) flags |= kFlagAo;
    if (!m_octree && m_radiance->options().anisotropic) flags |= kFlagAnisotropic;
    GpuGatherParams g{};
    g.gridMinV0 = glm::vec4(m_grid.origin(), v0);
    g.gridMaxStep =
        glm::vec4(m_grid.origin() + glm::vec3(m_grid.side()), p.getFloat("step_factor"));
    g.distances = glm::vec4(p.getFloat("max_distance") * m_grid.side(), 0.0f,
                            p.getFloat("opacity_cutoff"), p.getFloat("ao_falloff"));
    // The octree's vertex-centred samples carry a surface's data further than cell-centred
    // voxels do (techniques/vct/svo.md "Lift"): its clearance adds octree_lift_extra cells.
    const float lift = p.getFloat("lift");
    const float octreeExtra = p.getFloat("octree_lift_extra");
    g.misc =
        glm::vec4(p.getFloat("lod_offset"), lift > 0.0f && m_octree ? lift + octreeExtra : lift,
                  p.getEnum("lift_rule") == "blend" ? 1.0f : 0.0f, 0.0f);
    g.coneSet = toGpu(cones);
    g.cameraPosition = glm::vec4(ctx.scene.camera.position, 1.0f);
    const uint32_t level0Rays = uint32_t(p.getInt("control_level0_rays"));
    if (level0Rays > 0) flags |= kFlagLevel0Rays;
    g.sizeFlags = glm::uvec4(ctx.width, ctx.height, flags, level0Rays);
    g.specular = glm::vec4(glm::radians(p.getFloat("specular_min_aperture_deg")),
                           glm::radians(60.0f), p.getFloat("origin_offset") * v0, 0.0f);
    g.grid = m_grid.gpu();
    m_params.upload(&g, sizeof(g));

    if (m_voxelViewStale && m_voxelView) {
        // Debug view only (untimed, as at set-up): the camera moved since it was rendered
        m_voxelView->record(cmd, ctx.scene.camera, VoxelDebugMode::Albedo);
        m_voxelViewStale = false;
    }

    PassScope pass(ctx, cmd, "trace");
    vk::memoryBarrier(cmd);  // G-buffer and the cleared indirect layer
    m_gather.bind(cmd);
    VkDescriptorSet sets[2] = {m_inputSet.handle(), m_voxelSet.handle()};
    vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, m_gatherLayout.handle(), 0, 2,
                            sets, 0, nullptr);
    vk::dispatch2D(cmd, ctx.width, ctx.height);
    vk::memoryBarrier(cmd);
}

std::vector<DebugView> VctTechnique::debugViews() {
    std::vector<DebugView> views;
    if (m_ao && m_aoImage.valid()) views.push_back({"ao", &m_aoImage});
    if (m_voxelView) views.push_back({"voxels", &m_voxelView->image()});
    return views;
}

GILAB_REGISTER_TECHNIQUE(VctTechnique)

}  // namespace gilab
