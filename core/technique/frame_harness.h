#pragma once
/**
 * Runs one technique on one scene: uploads the scene, builds the shared passes, sets the
 * technique up (timed apart from frames), records and submits frames with per-pass GPU
 * timestamps, and reads the layers back as linear HDR images.
 *
 * Frame = shared passes (G-buffer, shadow maps, direct light) + technique.render() writing the
 * indirect layer. Composition final = emission + direct + indirect happens on read-back, in one
 * place (readLayers), so every technique is composed the same way.
 */
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "core/image/image.h"
#include "core/params/params.h"
#include "core/scene/animation.h"
#include "core/scene/scene.h"
#include "core/technique/technique.h"
#include "core/vk/timer.h"

namespace gilab {

struct SharedPassSettings;

/** Parameters of the shared passes, owner "shared" (set as shared.<key> on the command line). */
std::vector<ParamSpec> sharedPassParamSpecs();
ParamSet defaultSharedParams();
SharedPassSettings sharedSettingsFromParams(const ParamSet& sharedParams);

struct SetupTiming {
    double sceneUploadMs = 0.0;     // CPU wall time: GpuScene creation (buffers, textures)
    double sharedSetupMs = 0.0;     // CPU wall time: shared pass creation (pipelines, images)
    double shadowMapsMs = 0.0;      // CPU wall time: first render of the (static) shadow maps
    double techniqueSetupMs = 0.0;  // CPU wall time of technique.setup()
    double totalMs = 0.0;
    std::vector<vk::PassTime> passes;  // GPU times of set-up passes recorded with the timer
    std::vector<std::pair<std::string, double>> cpuPasses;  // CPU set-up passes (timeCpu), ms
};

struct FrameTiming {
    double cpuMs = 0.0;  // record + submit + wait, CPU wall time (update work included)
    std::vector<vk::PassTime> passes;
    // A dynamic frame (lights, camera or geometry changed since the previous frame) also runs
    // the update: GpuScene light upload, pass light table, the technique's update().
    bool dynamic = false;
    UpdateKind update = UpdateKind::None;
    double updateCpuMs = 0.0;                // CPU wall time of the update before the frame
    std::vector<vk::PassTime> updatePasses;  // GPU times of the technique's update submissions
};

/** Bytes of device memory by owner: "scene", "shared", the technique id, ... */
struct MemoryReport {
    uint64_t totalBytes = 0;
    uint64_t peakBytes = 0;
    std::vector<std::pair<std::string, uint64_t>> byOwner;
    std::vector<std::pair<std::string, uint64_t>> byTag;
};

/** What FrameHarness::warmUp() did. */
struct WarmupResult {
    int requested = 0;  // the config's warm-up frames
    int run = 0;        // frames rendered (more while the technique had not settled)
    bool settled = true;
};

class FrameHarness {
public:
    FrameHarness(vk::Context& ctx, const Scene& scene, const std::string& techniqueId,
                 const ParamSet& techniqueParams, const ParamSet& sharedParams);
    ~FrameHarness();
    FrameHarness(const FrameHarness&) = delete;
    FrameHarness& operator=(const FrameHarness&) = delete;

    const TechniqueInfo& info() const;
    /** Whether the technique can run on the scene (decided in the constructor). */
    const SupportResult& support() const { return m_support; }

    /** Throws gilab::Error if the technique does not support the scene. */
    SetupTiming setup();
    /**
     * Moves the scene to `state` (lights, camera: a frame of its animation, in world
     * coordinates; moved by -renderOrigin() here). The changes are
     * applied by the next renderFrame(), which is then a dynamic frame. Returns what changed
     * (accumulated with changes not rendered yet).
     */
    SceneChanges setFrameState(const SceneFrameState& state);
    FrameTiming renderFrame();
    /**
     * Warm-up: renders `frames` frames, then more until the technique is settled() or
     * kMaxWarmupFrames in all (none when frames = 0: an explicit cold start) (docs/timing.md
     * "Warm-up"). onFrame(i) after each frame.
     */
    WarmupResult warmUp(int frames, const std::function<void(int)>& onFrame = {});
    static constexpr int kMaxWarmupFrames = 64;
    /** The scene as it is now (the harness's own copy; animated frames change it), moved by
     *  -renderOrigin(): every pass and technique works in these coordinates. */
    const Scene& scene() const { return m_scene; }
    /** The world position of the passes' origin (scene.h renderOrigin: the bounds' centre in
     *  whole metres), so a scene far from the world's origin keeps the floats' precision. */
    const glm::dvec3& renderOrigin() const { return m_renderOrigin; }
    /** Frames without timestamp queries (to measure the instrumentation's own cost). */
    void setTimestampsEnabled(bool enabled) { m_timestamps = enabled; }
    /** Changes technique parameters between frames; calls onParamsChanged with changed keys. */
    void updateParams(const ParamSet& techniqueParams);

    /** final, indirect, direct, emission, albedo, normal, depth, then the debug views. */
    std::vector<ImageLayer> readLayers();

    /**
     * A VPL technique's last frame for the same-VPL reference: its VPL set and the G-buffer's
     * position (xyzw, in scene()'s coordinates), shading normal and albedo. False when the
     * technique has no VPLs.
     */
    bool readVplFrame(VplSet& vpls, Image& position, Image& normal, Image& albedo);

    const std::vector<std::string>& skipped() const { return m_skipped; }
    const std::vector<std::string>& notes() const { return m_notes; }
    /** Named numbers the technique reported (TechniqueContext::stat). */
    const std::vector<std::pair<std::string, double>>& stats() const { return m_stats; }
    MemoryReport memory() const;

private:
    TechniqueContext makeContext();

    vk::Context& m_ctx;
    /** Adds a note when a technique that claims indirect bounces returns a black indirect layer
     *  on a frame whose direct light is not black (it lit nothing: a silent failure otherwise). */
    void noteIfLightsNothing(const Image& indirect, const Image& direct);

    glm::dvec3 m_renderOrigin{0.0};
    Scene m_scene;  // own copy, moved by -m_renderOrigin: setFrameState moves its lights, camera
    SceneChanges m_pending;
    std::unique_ptr<Technique> m_technique;
    ParamSet m_params;
    ParamSet m_sharedParams;
    SupportResult m_support;
    std::unique_ptr<vk::GpuScene> m_gpuScene;
    std::unique_ptr<SharedPasses> m_shared;
    std::unique_ptr<vk::Image> m_indirect;
    std::unique_ptr<vk::GpuTimer> m_timer;
    std::vector<std::string> m_skipped;
    std::vector<std::string> m_notes;
    std::vector<std::pair<std::string, double>> m_stats;
    std::vector<PassTimeRecord> m_setupTimes;
    bool m_ready = false;
    bool m_timestamps = true;
};

}  // namespace gilab
