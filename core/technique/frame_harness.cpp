#include "core/technique/frame_harness.h"

#include <algorithm>
#include <map>

#include "core/gpu/gpu_scene.h"
#include "core/passes/shared_passes.h"
#include "core/scene/scene.h"
#include "core/technique/registry.h"
#include "core/util/error.h"
#include "core/util/progress.h"
#include "core/vk/context.h"
#include "core/vk/image.h"
#include "core/vpl/vpl.h"

namespace gilab {
namespace {

std::unique_ptr<vk::Image> makeFrameImage(vk::Context& ctx, uint32_t w, uint32_t h,
                                          const std::string& name) {
    vk::ImageDesc desc;
    desc.format = VK_FORMAT_R32G32B32A32_SFLOAT;
    desc.width = w;
    desc.height = h;
    desc.usage = VK_IMAGE_USAGE_STORAGE_BIT | VK_IMAGE_USAGE_SAMPLED_BIT |
                 VK_IMAGE_USAGE_TRANSFER_SRC_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT;
    desc.name = name;
    return std::make_unique<vk::Image>(ctx, desc);
}

/** Reads an RGBA32F (or other float-convertible) image into a CPU image of `channels`. */
Image readImage(vk::Context& ctx, vk::Image& image, int channels) {
    uint32_t srcChannels = 0;
    const std::vector<float> texels = image.readbackFloat(ctx, 0, 0, &srcChannels);
    const int w = int(image.desc().width), h = int(image.desc().height);
    Image out(w, h, channels);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            for (int c = 0; c < channels; ++c) {
                const size_t i = (size_t(y) * size_t(w) + size_t(x)) * srcChannels;
                out.at(x, y, c) = c < int(srcChannels) ? texels[i + size_t(c)] : 0.0f;
            }
    return out;
}

}  // namespace

FrameHarness::FrameHarness(vk::Context& ctx, const Scene& scene, const std::string& techniqueId,
                           const ParamSet& techniqueParams, const ParamSet& sharedParams)
    : m_ctx(ctx),
      m_renderOrigin(gilab::renderOrigin(scene)),
      m_scene(scene),
      m_technique(TechniqueRegistry::instance().create(techniqueId)),
      m_params(techniqueParams),
      m_sharedParams(sharedParams) {
    if (m_params.owner() != techniqueId)
        throw Error("parameters of \"" + m_params.owner() + "\" given to technique \"" +
                    techniqueId + "\"");
    if (m_renderOrigin != glm::dvec3(0.0)) translateScene(m_scene, -m_renderOrigin);
    m_support = m_technique->checkSupport(scene, m_params);
    if (scene.triangleCount() == 0) m_support = {false, "the scene has no triangles"};
    if (scene.settings.width < 1 || scene.settings.height < 1)
        m_support = {false, "the scene's resolution is empty"};
}

FrameHarness::~FrameHarness() = default;

const TechniqueInfo& FrameHarness::info() const {
    return m_technique->info();
}

TechniqueContext FrameHarness::makeContext() {
    TechniqueContext ctx{m_ctx,
                         m_scene,
                         *m_gpuScene,
                         *m_shared,
                         m_params,
                         uint32_t(m_scene.settings.width),
                         uint32_t(m_scene.settings.height),
                         m_timer.get(),
                         &m_skipped,
                         &m_notes,
                         m_technique->info().id,
                         &m_setupTimes,
                         &m_stats};
    return ctx;
}

SetupTiming FrameHarness::setup() {
    if (!m_support.supported)
        throw Error(m_technique->info().id + " cannot run on " + m_scene.name + ": " +
                    m_support.reason);
    SetupTiming t;
    const uint32_t w = uint32_t(m_scene.settings.width), h = uint32_t(m_scene.settings.height);
    Stopwatch total;

    Stopwatch sw;
    m_gpuScene = std::make_unique<vk::GpuScene>(m_ctx, m_scene);
    t.sceneUploadMs = sw.elapsedMs();

    sw.restart();
    m_shared = std::make_unique<SharedPasses>(m_ctx, *m_gpuScene, w, h,
                                              sharedSettingsFromParams(m_sharedParams));
    for (const std::string& s : m_shared->skippedPasses())
        m_skipped.push_back("shared/" + s);
    m_indirect = makeFrameImage(m_ctx, w, h, "shared/frame.indirect");
    m_timer = std::make_unique<vk::GpuTimer>(m_ctx, 128);
    t.sharedSetupMs = sw.elapsedMs();

    // Static lights and geometry: the shadow maps are rendered once, as set-up work.
    sw.restart();
    m_ctx.submitAndWait([&](VkCommandBuffer cmd) {
        m_timer->reset(cmd);
        m_shared->recordShadows(cmd, m_timer.get());
    });
    t.shadowMapsMs = sw.elapsedMs();
    t.passes = m_timer->resolve();

    sw.restart();
    m_setupTimes.clear();
    TechniqueContext ctx = makeContext();
    m_technique->setup(ctx);
    t.techniqueSetupMs = sw.elapsedMs();
    for (const PassTimeRecord& p : m_setupTimes) {
        if (p.cpuMs >= 0.0)
            t.cpuPasses.emplace_back(p.name, p.cpuMs);
        else
            t.passes.push_back({p.name, p.gpuMs, 0.0});
    }
    t.totalMs = total.elapsedMs();
    m_ready = true;
    return t;
}

SceneChanges FrameHarness::setFrameState(const SceneFrameState& worldState) {
    if (worldState.lights.size() != m_scene.lights.size())
        throw Error("setFrameState: " + std::to_string(worldState.lights.size()) +
                    " lights for a scene with " + std::to_string(m_scene.lights.size()));
    // Into the passes' coordinates (as the constructor moved the scene)
    SceneFrameState state = worldState;
    auto moved = [&](const glm::vec3& p) { return glm::vec3(glm::dvec3(p) - m_renderOrigin); };
    for (Light& l : state.lights)
        if (l.type != LightType::Directional) l.position = moved(l.position);
    state.camera.position = moved(state.camera.position);
    state.camera.target = moved(state.camera.target);
    const SceneChanges changes =
        diffFrameStates(SceneFrameState{m_scene.lights, m_scene.camera}, state);
    applyFrameState(m_scene, state);
    for (uint32_t i : changes.lights)
        if (std::find(m_pending.lights.begin(), m_pending.lights.end(), i) ==
            m_pending.lights.end())
            m_pending.lights.push_back(i);
    m_pending.camera = m_pending.camera || changes.camera;
    m_pending.geometry = m_pending.geometry || changes.geometry;
    return m_pending;
}

WarmupResult FrameHarness::warmUp(int frames, const std::function<void(int)>& onFrame) {
    WarmupResult w;
    w.requested = frames;
    const auto more = [&] {
        return frames > 0 && w.run < kMaxWarmupFrames && !m_technique->settled();
    };
    for (; w.run < frames || more(); ++w.run) {
        renderFrame();
        if (onFrame) onFrame(w.run);
    }
    w.settled = m_technique->settled();
    return w;
}

FrameTiming FrameHarness::renderFrame() {
    if (!m_ready) throw Error("FrameHarness::renderFrame() called before setup()");
    FrameTiming t;
    Stopwatch sw;
    TechniqueContext ctx = makeContext();
    vk::GpuTimer* timer = m_timestamps ? m_timer.get() : nullptr;
    ctx.timer = timer;
    if (m_pending.any()) {
        // The dynamic part: shared state first (lights buffer, pass light table), then the
        // technique's update (its own timed submissions), all inside this frame's time.
        t.dynamic = true;
        Stopwatch update;
        if (!m_pending.lights.empty() || m_pending.camera) {
            if (!m_pending.lights.empty()) {
                m_gpuScene->updateLights(m_pending.lights);
                m_shared->updateLights(m_pending.lights);
            }
            if (m_pending.camera) m_shared->updateCamera();
            m_ctx.submitAndWait([&](VkCommandBuffer cmd) {
                if (timer) timer->reset(cmd);
                m_shared->recordShadowUpdates(cmd, timer);
            });
            if (timer)
                for (const vk::PassTime& p : timer->resolve())
                    t.updatePasses.push_back(p);
        }
        m_setupTimes.clear();
        TechniqueContext uctx = makeContext();
        uctx.timer = timer;  // submitTimed resets and resolves it per submission
        t.update = m_technique->update(uctx, m_pending);
        for (const PassTimeRecord& p : m_setupTimes)
            if (p.cpuMs < 0.0) t.updatePasses.push_back({p.name, p.gpuMs, 0.0});
        m_setupTimes.clear();
        t.updateCpuMs = update.elapsedMs();
        m_pending = SceneChanges{};
    }
    m_ctx.submitAndWait([&](VkCommandBuffer cmd) {
        if (timer) timer->reset(cmd);
        m_shared->record(cmd, m_scene.camera, timer);
        m_indirect->clearColor(cmd, VkClearColorValue{{0.0f, 0.0f, 0.0f, 0.0f}});
        FrameTargets targets{*m_indirect, m_shared->direct()};
        m_technique->render(ctx, cmd, targets);
    });
    t.cpuMs = sw.elapsedMs();
    m_technique->frameFinished(ctx);
    if (timer) t.passes = timer->resolve();
    return t;
}

void FrameHarness::updateParams(const ParamSet& techniqueParams) {
    const std::vector<std::string> changed = m_params.changedKeys(techniqueParams);
    m_params = techniqueParams;
    if (changed.empty() || !m_ready) return;
    TechniqueContext ctx = makeContext();
    m_technique->onParamsChanged(ctx, changed);
}

std::vector<ImageLayer> FrameHarness::readLayers() {
    if (!m_ready) throw Error("FrameHarness::readLayers() called before setup()");
    GBuffer& gb = m_shared->gbuffer();
    Image indirect = readImage(m_ctx, *m_indirect, 3);
    Image direct = readImage(m_ctx, m_shared->direct(), 3);
    Image emission = readImage(m_ctx, gb.emission, 3);
    Image albedo = readImage(m_ctx, gb.albedo, 3);
    Image normal = readImage(m_ctx, gb.normal, 3);
    Image position = readImage(m_ctx, gb.position, 4);

    noteIfLightsNothing(indirect, direct);

    // Compose final = emission + direct + indirect, the same way for every technique.
    Image final(indirect.width(), indirect.height(), 3);
    for (size_t i = 0; i < final.values().size(); ++i)
        final.values()[i] = emission.values()[i] + direct.values()[i] + indirect.values()[i];

    // Depth = distance along the camera's forward axis; 0 where there is no geometry.
    Image depth = computeLinearDepth(position.values(), uint32_t(position.width()),
                                     uint32_t(position.height()), m_scene.camera);

    std::vector<ImageLayer> layers;
    layers.push_back({"final", std::move(final)});
    layers.push_back({"indirect", std::move(indirect)});
    layers.push_back({"direct", std::move(direct)});
    layers.push_back({"emission", std::move(emission)});
    layers.push_back({"albedo", std::move(albedo)});
    layers.push_back({"normal", std::move(normal)});
    layers.push_back({"depth", std::move(depth)});
    for (const DebugView& view : m_technique->debugViews())
        if (view.image) layers.push_back({"debug_" + view.name, readImage(m_ctx, *view.image, 3)});
    return layers;
}

void FrameHarness::noteIfLightsNothing(const Image& indirect, const Image& direct) {
    if (claimedBounces(m_technique->info(), m_params) == 0) return;
    const auto lit = [](const Image& im) {
        for (float v : im.values())
            if (v > 0.0f) return true;
        return false;
    };
    if (lit(indirect) || !lit(direct)) return;
    const std::string note = m_technique->info().id +
                             " lights nothing: its indirect layer is black on every pixel while "
                             "the direct light is not (see its stats for what it found lit)";
    for (const std::string& n : m_notes)
        if (n == note) return;
    m_notes.push_back(note);
}

bool FrameHarness::readVplFrame(VplSet& vpls, Image& position, Image& normal, Image& albedo) {
    if (!m_ready) throw Error("FrameHarness::readVplFrame() called before setup()");
    if (!m_technique->readVplSet(vpls)) return false;
    GBuffer& gb = m_shared->gbuffer();
    position = readImage(m_ctx, gb.position, 4);
    normal = readImage(m_ctx, gb.normal, 3);
    albedo = readImage(m_ctx, gb.albedo, 3);
    return true;
}

MemoryReport FrameHarness::memory() const {
    MemoryReport report;
    const vk::MemoryTracker& tracker = m_ctx.memory();
    report.totalBytes = tracker.total();
    report.peakBytes = tracker.peak();
    std::map<std::string, uint64_t> owners;
    for (const auto& [tag, bytes] : tracker.byTag()) {
        report.byTag.emplace_back(tag, bytes);
        const size_t slash = tag.find('/');
        owners[slash == std::string::npos ? tag : tag.substr(0, slash)] += bytes;
    }
    report.byOwner.assign(owners.begin(), owners.end());
    return report;
}

}  // namespace gilab
