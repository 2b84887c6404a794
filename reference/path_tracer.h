#pragma once
/**
 * The ground truth: a CPU path tracer on Embree 3 + TBB that renders the same Scene, camera,
 * materials and lights as the Vulkan techniques (docs/conventions.md), with an exact split of
 * the light by bounce.
 *
 * Layers (linear HDR radiance, RGB):
 *   emission     emitted radiance seen directly by the camera
 *   direct       light -> first visible surface -> eye
 *   bounce1      light after exactly one indirect bounce (light -> surface -> surface -> eye)
 *   bounce2      exactly two indirect bounces
 *   bounce3plus  three or more (up to maxBounces)
 *   full         the sum of the five above (its own variance is tracked, not summed)
 * A technique that claims n indirect bounces is compared with emission + direct + bounce1..n.
 *
 * Determinism: every random number is a hash of (seed, pixel, sample index, dimension), each
 * pixel's samples are added in sample order by one thread, so the same seed and settings give
 * the same image bit for bit whatever the thread count, and adding samples [N, 2N) to a stored
 * N-sample accumulator gives exactly the 2N-sample image.
 */
#include <atomic>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "core/image/image.h"
#include "core/scene/scene.h"
#include "reference/reference_settings.h"
#include "reference/sampling.h"

namespace gilab::ref {

/**
 * Running sums per layer, pixel and channel (double), enough to continue a render and to
 * estimate the per-pixel variance of every layer. Index: ((layer * height + y) * width + x) * 3 +
 * c.
 *
 * With the Sobol sampler the samples of a pixel are not independent, so the sample variance
 * over-estimates the error. Its samples come in replicates of `replicate` samples, each an
 * independently scrambled sequence (Sampler); the accumulator then also keeps, per value, the
 * sum of squares of the finished replicates' sums and the open replicate's running sum, and the
 * error is estimated from the spread of the replicates (docs/reference.md, "Samplers").
 */
struct Accumulator {
    int width = 0;
    int height = 0;
    uint64_t samples = 0;  // per pixel, the same for every pixel
    /** Samples (over all pixels) dropped because some layer was NaN or Inf: they add 0 to the
     *  sums but count in `samples` (docs/reference.md, "Non-finite samples"). */
    uint64_t nonFiniteSamples = 0;
    std::vector<double> sum;
    std::vector<double> sumSq;
    /** Samples per replicate (a power of two), 0 = independent samples: no replicate sums. */
    uint32_t replicate = 0;
    std::vector<double> replicateSumSq;  // sum over finished replicates of (replicate sum)^2
    std::vector<double> replicateOpen;   // the unfinished replicate's sum so far

    /** Errors come from the replicates' spread once this many have finished; before, from the
     *  sample variance (conservative for Sobol). */
    static constexpr uint64_t kMinReplicates = 8;

    /** Zero sums of w x h pixels; replicate > 0 also keeps the replicate sums. */
    void reset(int w, int h, uint32_t replicate = 0);
    size_t index(Layer layer, int x, int y, int c) const {
        return ((size_t(layer) * size_t(height) + size_t(y)) * size_t(width) + size_t(x)) * 3 +
               size_t(c);
    }
    double mean(Layer layer, int x, int y, int c) const;
    /** Standard error of the mean, 0 with < 2 samples: sqrt(sample variance / samples), or with
     *  >= kMinReplicates finished replicates sqrt(variance of a replicate's sum / replicate /
     *  samples). */
    double stdError(Layer layer, int x, int y, int c) const;
    /** Whether stdError uses the replicates' spread. */
    bool replicateErrors() const { return replicate > 0 && samples / replicate >= kMinReplicates; }
};

/** The mean (or standard-error) image of one layer, RGB. */
Image meanImage(const Accumulator& acc, Layer layer);
Image stdErrorImage(const Accumulator& acc, Layer layer);
/** Mean images, named by layerName(), in Layer order. */
std::vector<ImageLayer> meanLayers(const Accumulator& acc);
/** Standard-error images, named "<layer>_stderr", in Layer order. */
std::vector<ImageLayer> stdErrorLayers(const Accumulator& acc);
/**
 * Mean over pixels of stderr / max(mean, eps) of the luminance of `layer`, over pixels whose
 * mean luminance exceeds eps (eps = 1e-3 x the image's mean luminance). The convergence
 * measure of the --rel-error stop criterion. The stderr of a luminance is bounded by the
 * luminance of the channel stderrs (no covariances are stored). Infinity with < 2 samples.
 */
double meanRelativeStdError(const Accumulator& acc, Layer layer = Layer::Full);

struct RayStats {
    uint64_t cameraRays = 0;
    uint64_t bounceRays = 0;  // closest-hit rays after the first
    uint64_t shadowRays = 0;  // occlusion rays for next-event estimation
    double seconds = 0.0;     // wall time inside addSamples
    /** Samples dropped for NaN/Inf in this tracer's addSamples calls (docs/reference.md). */
    uint64_t nonFiniteSamples = 0;
    uint64_t totalRays() const { return cameraRays + bounceRays + shadowRays; }
};

class EmbreeScene;

/**
 * Where the tracer's coordinates have their origin. Camera (default): the scene is moved so the
 * camera sits at the origin (as pbrt-v4's camera-world rendering space), so the floats are
 * finest where the image is, and a scene moved by an exact amount renders the same wherever it
 * sits. World: the scene's own coordinates (tests of the ray offsets far from the origin).
 * The images do not depend on it beyond float rounding (docs/reference.md, "Ray origins").
 */
enum class RenderSpace { Camera, World };

class PathTracer {
public:
    /** Builds the Embree scene (BVH), light sampling tables and texture lookups. */
    PathTracer(const Scene& scene, const ReferenceSettings& settings,
               RenderSpace space = RenderSpace::Camera);
    ~PathTracer();
    PathTracer(const PathTracer&) = delete;
    PathTracer& operator=(const PathTracer&) = delete;

    /**
     * Adds samples [acc.samples, acc.samples + count) to every pixel, in parallel over tiles
     * (TBB). If `cancel` becomes true the batch is abandoned and `acc` is left as it was;
     * returns false then. `acc` must be reset to the scene's resolution.
     */
    bool addSamples(Accumulator& acc, uint32_t count, const std::atomic<bool>* cancel = nullptr);

    const RayStats& stats() const;
    /** Exact description of the settings, embedded in every sidecar. */
    std::string toString() const;
    /** The scene as traced (moved to the render space). */
    const Scene& scene() const;
    const ReferenceSettings& settings() const;
    /** The Embree scene (for benchmarks). */
    EmbreeScene& embree();

    /** Records every ray traced by later addSamples calls (single-threaded use only). */
    void recordRays(std::vector<RecordedRay>* sink);

private:
    struct Impl;
    std::unique_ptr<Impl> m_impl;
};

enum class StopReason { Samples, RelError, Time, Cancelled };
const char* stopReasonName(StopReason r);  // "samples", "rel_error", "time", "cancelled"

struct ConvergencePoint {
    uint64_t samples;
    double seconds;
    double relError;      // meanRelativeStdError(full)
    double relMseVsLong;  // relative MSE of full vs a given longer reference, or NaN
};

struct RenderReport {
    StopReason reason = StopReason::Samples;
    uint64_t samples = 0;
    double seconds = 0.0;
    double cpuSeconds = 0.0;  // CPU time of the process meanwhile (every thread)
    double relError = 0.0;
    RayStats rays;
    std::vector<ConvergencePoint> curve;  // one point per batch
};

/**
 * Adds batches of settings().batchSamples until a criterion is met, with a progress line
 * (samples/s, ETA). `longReference` (the full layer of a longer render, RGB) adds the relative
 * MSE against it to every curve point.
 */
RenderReport renderUntil(PathTracer& tracer, Accumulator& acc, const StopCriteria& stop,
                         const std::atomic<bool>* cancel = nullptr,
                         const Image* longReference = nullptr);

/** Relative MSE: mean over pixels and channels of (a - b)^2 / (b^2 + 1e-2) (docs/reference.md). */
double relativeMse(const Image& a, const Image& b);

}  // namespace gilab::ref
