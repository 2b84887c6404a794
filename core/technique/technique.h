#pragma once
/**
 * The Technique interface every GI method implements, plugin style.
 *
 * A technique lives in techniques/<id>/ (C++) and shaders/<id>/ (GLSL), has one line in the
 * top-level CMake technique table, and registers itself with GILAB_REGISTER_TECHNIQUE at the end
 * of its .cpp. Nothing in core/ names a technique.
 *
 * Life cycle (driven by the harness, core/technique/frame_harness.h):
 *   info()            static description: id, parameters, claimed bounces, supported features
 *   checkSupport()    can it run on this scene? If not, the harness skips it with the reason
 *   setup()           precomputation (voxelization, clustering, ...), timed apart from frames
 *   onParamsChanged() only the keys that changed; the default re-runs setup() for Rebuild keys
 *   update()          lights, camera or geometry changed (an animated scene): do what the paper
 *                     does on such a change as named, timed passes; the default re-runs setup()
 *                     and is reported as a "full rebuild"
 *   render()          records the per-frame passes into the frame's command buffer; it must write
 *                     the indirect layer (linear HDR radiance, RGBA32F) and may add debug views
 *   frameFinished()   after the frame's submission: per-frame numbers read back (ctx.stat)
 * The harness owns the shared passes (G-buffer, shadow maps, direct light), the composition
 * final = emission + direct + indirect, timing, read-back, NaN/Inf counting and memory reports.
 */
#include <functional>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <vulkan/vulkan.h>

#include "core/params/params.h"

namespace gilab {

struct Scene;
struct SceneChanges;
struct VplSet;

class SharedPasses;
struct GBuffer;
namespace vk {
class Context;
class Image;
class GpuTimer;
class GpuScene;
}  // namespace vk

/** Number of indirect bounces a technique claims; compared with the matching reference. */
inline constexpr int kAllBounces = -1;

/** Scene features a technique can consume. */
struct FeatureSupport {
    bool pointLights = true;
    bool spotLights = true;
    bool directionalLights = true;
    bool emissiveSurfaces = true;  // emitters as light sources for the indirect light
};

struct TechniqueInfo {
    std::string id;           // = the folder name, snake_case
    std::string description;  // one line
    std::string citation;     // the paper it implements ("" for the baseline)
    std::vector<ParamSpec> params;
    int indirectBounces = 0;  // 0 = direct only, n >= 1, or kAllBounces
    /** When set, the int parameter whose value is the claimed bounce count (e.g. dvs "bounces");
     *  indirectBounces is then its default. Use claimedBounces() to read it. */
    std::string bouncesParam;
    FeatureSupport supports;
    /** Optional cross-parameter check (e.g. "gaussian_kernel must be odd") beyond each spec's
     *  range: throws gilab::Error naming the parameter. Experiment configs call it for every
     *  sweep point before anything runs; set-up calls it again through the settings parser. */
    std::function<void(const ParamSet&)> checkParams;
};

/** The indirect bounces a technique claims with these parameter values (TechniqueInfo). */
int claimedBounces(const TechniqueInfo& info, const ParamSet& params);

struct SupportResult {
    bool supported = true;
    std::string reason;  // why not, e.g. "needs a shadow-mapped light; scene has only emitters"
};

/** A named image a technique exposes for inspection (written to the EXR as an extra layer). */
struct DebugView {
    std::string name;
    vk::Image* image = nullptr;  // RGBA32F at frame resolution, GENERAL or SHADER_READ_ONLY layout
};

/** A GPU time measured during set-up (see TechniqueContext::submitTimed). */
struct PassTimeRecord {
    std::string name;
    double gpuMs = 0.0;
    double cpuMs = -1.0;  // >= 0: a set-up pass that ran on the CPU (TechniqueContext::timeCpu)
};

/** What a technique sees while it sets up and renders. */
struct TechniqueContext {
    vk::Context& vk;
    const Scene& scene;
    const vk::GpuScene& gpuScene;
    SharedPasses& shared;  // G-buffer, shadow maps, direct light (core/passes/shared_passes.h)
    const ParamSet& params;
    uint32_t width = 0;
    uint32_t height = 0;
    vk::GpuTimer* timer = nullptr;  // may be null: name passes with PassScope, not directly
    std::vector<std::string>* skipped = nullptr;  // "pass: reason" lines for the run's metadata
    std::vector<std::string>* notes = nullptr;    // other facts worth recording

    /** Memory tag for a resource owned by the running technique: "<id>/<resource>". */
    std::string tag(const std::string& resource) const;
    void skip(const std::string& pass, const std::string& reason) const;
    void note(const std::string& text) const;
    /** A named number of the run (counts, sizes: e.g. "clusters"), stored in the result as
     *  stats.<name> and as a stat.<name> column; a later value of the same name replaces it. */
    void stat(const std::string& name, double value) const;
    /**
     * For set-up work on the GPU: records with `record` (use PassScope inside to name the
     * passes, e.g. "voxelize"), submits and waits; the pass times are added to the run's set-up
     * timing. Not for use inside render().
     */
    void submitTimed(const std::function<void(VkCommandBuffer)>& record) const;
    /** For set-up work on the CPU: runs `work` and records its wall time as the CPU pass
     *  "<technique id>/<name>" of the run's set-up timing (setup_cpu_passes). */
    void timeCpu(const std::string& name, const std::function<void()>& work) const;
    std::string techniqueId;
    std::vector<PassTimeRecord>* setupTimes = nullptr;  // internal: filled by submitTimed
    std::vector<std::pair<std::string, double>>* stats = nullptr;  // internal: filled by stat
};

/**
 * Times one pass of a technique with GPU timestamps, named "<technique id>/<name>":
 *     { PassScope pass(ctx, cmd, "inject"); ...record... }
 * Does nothing when the harness runs without timestamps.
 */
class PassScope {
public:
    PassScope(const TechniqueContext& ctx, VkCommandBuffer cmd, const std::string& name);
    ~PassScope();
    PassScope(const PassScope&) = delete;
    PassScope& operator=(const PassScope&) = delete;

private:
    vk::GpuTimer* m_timer;
    VkCommandBuffer m_cmd;
};

/** What a technique did about a scene change (Technique::update), recorded per frame. */
enum class UpdateKind {
    None,         // nothing to redo (e.g. only the camera moved and nothing depends on it)
    Incremental,  // the technique's own update passes (what its paper does on a change)
    FullRebuild,  // set-up re-run: the technique has no real update path
};
const char* updateKindName(UpdateKind kind);  // "none", "incremental", "full rebuild"

/** The images of one frame. `indirect` is cleared to zero before render() is called. */
struct FrameTargets {
    vk::Image& indirect;  // RGBA32F storage image, GENERAL layout: write indirect radiance here
    vk::Image& direct;    // shared direct light; a technique may overwrite it (declare it in notes)
};

class Technique {
public:
    virtual ~Technique() = default;

    /** Default: compares the scene's lights and emitters with info().supports. */
    virtual SupportResult checkSupport(const Scene& scene, const ParamSet& params) const;
    virtual void setup(TechniqueContext& ctx) = 0;
    /** Default: runs setup() again when any changed key has stage Rebuild. */
    virtual void onParamsChanged(TechniqueContext& ctx, const std::vector<std::string>& keys);
    /**
     * Called before a frame when lights, camera or geometry changed since the previous frame.
     * ctx.scene already holds the new state, and the shared passes are updated: the GpuScene
     * light buffer, the pass light table and the moved lights' shadow maps (re-rendered in a
     * finished submission before update() is called, so update passes may read them). Record
     * update passes with ctx.submitTimed + PassScope (their GPU times count as this frame's
     * update).
     * Default: setup() again when anything changed (FullRebuild), else None.
     */
    virtual UpdateKind update(TechniqueContext& ctx, const SceneChanges& changes);
    /** Records the frame's passes. Must not submit; the harness submits and waits. */
    virtual void render(TechniqueContext& ctx, VkCommandBuffer cmd, FrameTargets& targets) = 0;
    /** Called once the frame's submission has finished: read back small per-frame results
     *  (e.g. counters) and record them with ctx.stat. Default: nothing. */
    virtual void frameFinished(TechniqueContext& ctx) { (void)ctx; }
    virtual std::vector<DebugView> debugViews() { return {}; }
    /** False while state the technique carries from frame to frame (ssvp's warm-started
     *  K-means) still changes on a static scene; FrameHarness::warmUp() renders warm-up frames
     *  until it is true (docs/timing.md "Warm-up"). Read after frameFinished(). */
    virtual bool settled() const { return true; }
    /** VPL techniques: the last frame's VPLs as the gather used them (read back after the
     *  frame), for the same-VPL shadow-ray reference. Default: false (not a VPL technique). */
    virtual bool readVplSet(VplSet& out) {
        (void)out;
        return false;
    }

    const TechniqueInfo& info() const { return m_info; }

private:
    friend class TechniqueRegistry;
    TechniqueInfo m_info;
};

}  // namespace gilab
