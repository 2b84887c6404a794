#pragma once
/**
 * Image metrics: a test image against the path-traced reference, both linear HDR RGB
 * (docs/conventions.md). Every definition, constant and rule is stated in docs/metrics.md.
 *
 *   MSE, RMSE, relMSE      linear HDR, mean over pixels and the three channels
 *   PSNR (LDR)             both images tonemapped with one ToneMap, 8-bit sRGB, peak 255
 *   PSNR (HDR)             linear, peak = the reference's maximum finite channel value
 *   SSIM                   Wang et al. 2004 on the Rec.709 luma of the tonemapped sRGB images
 *   FLIP                   LDR-FLIP (Andersson et al. 2020) and HDR-FLIP (Andersson et al. 2021)
 *   Temporal instability   a sequence's frame-to-frame change against the reference's
 *
 * Inputs have 3 or 4 channels (a 4th is ignored) and equal sizes; anything else throws
 * gilab::Error. Non-finite pixels are never averaged away: every result carries the counts of
 * NaN/Inf pixels of each input and a flag, and its value is over the finite pixels only.
 * A metric may be restricted to a region Mask. Spatial metrics (SSIM, FLIP) are computed on the
 * whole image and pooled over the region.
 */
#include <cstddef>
#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/image/image.h"
#include "core/image/image_io.h"

namespace gilab::metrics {

inline constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
inline constexpr double kInf = std::numeric_limits<double>::infinity();

/** relMSE's ε: (t − r)² / (r² + ε); the same value as gilab::ref::relativeMse. */
inline constexpr double kRelMseEpsilon = 1.0e-2;
/** FLIP's default pixels per degree: 0.7 m from a 0.7 m wide 3840-px monitor. */
inline constexpr double kDefaultPpd = 67.0;

// ---------------------------------------------------------------------------------------------
// Regions
// ---------------------------------------------------------------------------------------------

/** Pixels [x, x + width) × [y, y + height), clipped to the image. */
struct PixelRect {
    int x = 0;
    int y = 0;
    int width = 0;
    int height = 0;
};
/** A rectangle in image fractions: pixel (x, y) is inside iff x0·W ≤ x + ½ < x1·W (and y). */
struct NormalizedRect {
    double x0 = 0.0;
    double y0 = 0.0;
    double x1 = 1.0;
    double y1 = 1.0;
};

/** One bool per pixel (row 0 = top), the region a metric is pooled over. */
class Mask {
public:
    Mask() = default;
    Mask(int width, int height, bool value = false);

    /** The union of pixel rectangles. */
    static Mask fromRects(int width, int height, const std::vector<PixelRect>& rects);
    /** The union of normalised rectangles. */
    static Mask fromNormalizedRects(int width, int height,
                                    const std::vector<NormalizedRect>& rects);
    /** Pixels whose channel 0 is > threshold (NaN is outside). */
    static Mask fromImage(const Image& image, float threshold = 0.5f);
    /**
     * Pixels where the reference's indirect light carries more than `percent` % of its total:
     * Y(indirect) > percent/100 · Y(full) and Y(full) > 0 (Rec.709 luminance, finite pixels).
     */
    static Mask fromIndirectFraction(const Image& refIndirect, const Image& refFull,
                                     double percent);

    int width() const { return m_width; }
    int height() const { return m_height; }
    bool empty() const { return m_data.empty(); }
    bool at(int x, int y) const { return m_data[size_t(y) * size_t(m_width) + size_t(x)] != 0; }
    void set(int x, int y, bool value) {
        m_data[size_t(y) * size_t(m_width) + size_t(x)] = value ? 1 : 0;
    }
    /** Pixels inside. */
    size_t count() const;
    Mask inverted() const;
    Mask intersected(const Mask& other) const;
    /** Row-major, 1 inside, 0 outside. */
    const std::vector<uint8_t>& values() const { return m_data; }

private:
    int m_width = 0;
    int m_height = 0;
    std::vector<uint8_t> m_data;
};

/** Which pixels a metric averages, and why others were left out. */
struct PixelSelection {
    std::vector<uint8_t> include;  // 1 = in the region and finite in every input
    size_t regionPixels = 0;       // pixels in the region (the whole image without a mask)
    size_t pixels = 0;             // pixels included
    size_t testNonFinite = 0;      // region pixels with a NaN/Inf in R, G or B of the test
    size_t refNonFinite = 0;       // ... of the reference (or of its stderr image)
    bool hasNonFinite() const { return testNonFinite + refNonFinite > 0; }
};
/** The selection for a pair of images (and an optional stderr image counted with the ref). */
PixelSelection selectPixels(const Image& test, const Image& reference, const Mask* mask,
                            const Image* referenceStdError = nullptr);

// ---------------------------------------------------------------------------------------------
// Per-pixel metrics
// ---------------------------------------------------------------------------------------------

/** One scalar metric: its value over the included pixels and the non-finite counts. */
struct ScalarResult {
    double value = kNaN;  // NaN when no pixel is included
    size_t pixels = 0;
    size_t testNonFinite = 0;
    size_t refNonFinite = 0;
    bool hasNonFinite() const { return testNonFinite + refNonFinite > 0; }
};

ScalarResult computeMse(const Image& test, const Image& reference, const Mask* mask = nullptr);
/** sqrt(MSE). */
ScalarResult computeRmse(const Image& test, const Image& reference, const Mask* mask = nullptr);
/** Mean of (t − r)² / (r² + kRelMseEpsilon); identical to gilab::ref::relativeMse. */
ScalarResult computeRelMse(const Image& test, const Image& reference, const Mask* mask = nullptr);
/** 10 log10(255² / MSE of the 8-bit sRGB values); +inf when they are equal. */
ScalarResult computePsnrLdr(const Image& test, const Image& reference, const ToneMap& tonemap,
                            const Mask* mask = nullptr);
/** 10 log10(peak² / MSE); peak defaults to getHdrPeak(reference). +inf when MSE is 0. */
ScalarResult computePsnrHdr(const Image& test, const Image& reference, const Mask* mask = nullptr,
                            std::optional<double> peak = std::nullopt);
/** The largest finite R, G or B value of the whole image (no mask); NaN if none. */
double getHdrPeak(const Image& reference);
/**
 * Mean Rec.709 luminance of the test's finite region pixels over the reference's, e.g. the
 * indirect layers: the energy a technique gathers relative to the ground truth. NaN if the
 * reference's mean is 0.
 */
double computeEnergyRatio(const Image& testLayer, const Image& referenceLayer,
                          const Mask* mask = nullptr);

// ---------------------------------------------------------------------------------------------
// SSIM
// ---------------------------------------------------------------------------------------------

struct SsimResult {
    ScalarResult mean;  // mean SSIM over the valid windows whose centre pixel is included
    /** 1 channel, (W − 10) × (H − 10): map(x, y) is the window centred on pixel (x+5, y+5). */
    Image map;
};
/** Tonemaps both (one ToneMap), then SSIM of their luma. Images must be at least 11 × 11. */
SsimResult computeSsim(const Image& test, const Image& reference, const ToneMap& tonemap,
                       const Mask* mask = nullptr);
/** SSIM of two 1-channel images in [0, 1] (L = 1). */
SsimResult computeSsimLuma(const Image& testLuma, const Image& refLuma, const Mask* mask = nullptr);

// ---------------------------------------------------------------------------------------------
// FLIP
// ---------------------------------------------------------------------------------------------

/** Pooled FLIP values over the included pixels (percentiles weighted by the error itself). */
struct FlipStats {
    double mean = kNaN;
    double weightedMedian = kNaN;
    double weightedP25 = kNaN;  // 1st weighted quartile
    double weightedP75 = kNaN;  // 3rd weighted quartile
    double weightedP95 = kNaN;
    double min = kNaN;
    double max = kNaN;
    size_t pixels = 0;
};

struct FlipResult {
    FlipStats stats;
    /** 1 channel, full size, values in [0, 1]; NaN at pixels left out (non-finite input). */
    Image errorMap;
    size_t testNonFinite = 0;
    size_t refNonFinite = 0;
    // HDR-FLIP only (NaN / 0 for LDR-FLIP):
    double startExposure = kNaN;  // c_start, in stops
    double stopExposure = kNaN;   // c_stop
    int exposureCount = 0;        // N
    bool hasNonFinite() const { return testNonFinite + refNonFinite > 0; }
};

/** HDR-FLIP exposure range; unset values are computed from the reference (2021 paper §2.1). */
struct HdrFlipOptions {
    double ppd = kDefaultPpd;
    std::optional<double> startExposure;
    std::optional<double> stopExposure;
    std::optional<int> exposureCount;
};
struct HdrExposures {
    double start = kNaN;
    double stop = kNaN;
    int count = 0;
};
/** c_start, c_stop and N from the reference's luminance (docs/metrics.md, HDR-FLIP). */
HdrExposures computeHdrExposures(const Image& refLinear, const HdrFlipOptions& options = {});
/** HDR-FLIP's tone mapper: the ACES fit of the 2021 paper §2.1, not clamped. */
double hdrFlipToneMap(double x);
/** Its inverse on [0, t(∞)). */
double hdrFlipToneMapInverse(double y);

/** LDR-FLIP of sRGB-encoded images in [0, 1] (values outside are clamped). */
FlipResult computeLdrFlip(const Image& testSrgb01, const Image& refSrgb01, double ppd = kDefaultPpd,
                          const Mask* mask = nullptr);
/** HDR-FLIP of linear HDR images. */
FlipResult computeHdrFlip(const Image& testLinear, const Image& refLinear,
                          const HdrFlipOptions& options, const Mask* mask = nullptr);
inline FlipResult computeHdrFlip(const Image& testLinear, const Image& refLinear,
                                 double ppd = kDefaultPpd) {
    return computeHdrFlip(testLinear, refLinear, HdrFlipOptions{.ppd = ppd});
}
/** Pools an error map (1 channel) over the pixels with include[i] != 0 (all if null). */
FlipStats poolFlip(const Image& errorMap, const std::vector<uint8_t>* include = nullptr);

// ---------------------------------------------------------------------------------------------
// Colour map
// ---------------------------------------------------------------------------------------------

/** Magma at t in [0, 1] (clamped), sRGB-encoded display values in [0, 1]. */
void getMagmaSrgb(double t, float rgb[3]);
/**
 * A 1-channel error map (values in [0, 1]) as magma, returned as LINEAR RGB so that
 * writePngTonemapped(path, image, ToneMap{}) writes the magma colours. Non-finite values stay
 * non-finite, so the PNG writer paints them magenta like every other preview.
 */
Image magmaColorize(const Image& errorMap);
/** writePngTonemapped(path, magmaColorize(errorMap), ToneMap{}). */
void writeMagmaPng(const std::string& path, const Image& errorMap);

// ---------------------------------------------------------------------------------------------
// Everything at once, with error bars from the reference's own noise
// ---------------------------------------------------------------------------------------------

struct NoiseFloorSamples;

struct MetricOptions {
    ToneMap tonemap;  // for PSNR (LDR), SSIM and LDR-FLIP
    double ppd = kDefaultPpd;
    std::optional<Mask> mask;
    /** Per pixel and channel standard error of the reference mean ("<layer>_stderr"). */
    const Image* referenceStdError = nullptr;
    int noiseResamples = 8;
    uint64_t noiseSeed = 0x6d657472696373ull;
    /** Resample FLIP too (the costliest part: 2 × noiseResamples HDR-FLIP evaluations). */
    bool resampleFlip = true;
    std::optional<double> hdrPeak;             // PSNR (HDR) peak; default getHdrPeak(reference)
    std::optional<HdrExposures> hdrExposures;  // default computeHdrExposures(reference)
    /**
     * The reference-only half of the resampled error bars, from computeNoiseFloor with this
     * reference and these options; computed by computeMetrics when null. Sharing it between
     * the test images compared with one reference halves the cost of the error bars.
     */
    const NoiseFloorSamples* noiseFloor = nullptr;
};

/**
 * M(r̂_k, r̂) for the noiseResamples draws r̂_k = r̂ + σ N(0, 1) of noiseSeed, for PSNR (LDR,
 * HDR), SSIM and (if resampleFlip) the HDR- and LDR-FLIP means, pooled over the region minus
 * the reference's (and stderr's) non-finite pixels. Depends only on the reference, its stderr
 * and the options, never on a test image.
 */
struct NoiseFloorSamples {
    std::vector<double> psnrLdr, psnrHdr, ssim, flip, flipLdr;
};
/** Needs options.referenceStdError. */
NoiseFloorSamples computeNoiseFloor(const Image& reference, const MetricOptions& options);

/** A resampled metric M: spread of M(test, r̂ + e_k) and M(r̂ + e_k, r̂) (the noise floor). */
struct ResampledBar {
    double spread = kNaN;       // sample std. dev. of M(test, r̂ + e_k): the ±1σ bar
    double floorMean = kNaN;    // mean of M(r̂ + e_k, r̂): what an exact image would score
    double floorSpread = kNaN;  // sample std. dev. of M(r̂ + e_k, r̂)
    bool withinNoise = false;   // M(test, r̂) is not worse than floorMean by > 2 floorSpread
};

struct ErrorBars {
    bool available = false;  // a referenceStdError image was given
    int resamples = 0;
    double mseNoiseFloor = kNaN;  // mean σ²
    double mseSigma = kNaN;       // ±1σ of the measured MSE
    double mseDebiased = kNaN;    // MSE − mean σ²
    double relMseNoiseFloor = kNaN;
    double relMseSigma = kNaN;
    double relMseDebiased = kNaN;
    ResampledBar psnrLdr, psnrHdr, ssim, flip, flipLdr;
};

struct MetricSet {
    double mse = kNaN, rmse = kNaN, relMse = kNaN;
    double psnrLdr = kNaN, psnrHdr = kNaN, psnrHdrPeak = kNaN;
    double ssim = kNaN;
    FlipStats flip;     // HDR-FLIP of the linear images
    FlipStats flipLdr;  // LDR-FLIP of the images tonemapped with options.tonemap
    HdrExposures flipExposures;
    size_t pixels = 0;        // pixels averaged (region ∩ finite)
    size_t regionPixels = 0;  // pixels in the region
    size_t testNonFinite = 0, refNonFinite = 0;
    bool hasNonFinite = false;
    ErrorBars bars;
    /** MSE ≤ 2 × its noise floor mean(σ²) (docs/metrics.md); false without a stderr image. */
    bool withinReferenceNoise = false;
};

/** Optional full-size maps for reports. */
struct MetricMaps {
    Image ssim;     // see SsimResult::map
    Image flip;     // HDR-FLIP
    Image flipLdr;  // LDR-FLIP
};

MetricSet computeMetrics(const Image& test, const Image& reference, const MetricOptions& options,
                         MetricMaps* maps = nullptr);

/** snake_case keys; non-finite numbers (e.g. PSNR +inf of equal images) are written as null. */
nlohmann::ordered_json toJson(const MetricSet& metrics);
nlohmann::ordered_json toJson(const FlipStats& stats);

// ---------------------------------------------------------------------------------------------
// Temporal instability (experiments/metrics/temporal.cpp; docs/metrics.md, "Temporal
// instability")
// ---------------------------------------------------------------------------------------------

/**
 * How much a technique's frame-to-frame change differs from the reference's over a sequence:
 * per pixel p and consecutive pair k, d_k(p) = |(Y(T_{k+1}) − Y(T_k)) − (Y(R_{k+1}) − Y(R_k))|
 * on Rec.709 luminance Y. Relative values are divided by the reference's level (its mean
 * luminance over all frames and region pixels). A technique that flickers or lags scores worse
 * even when each frame on its own looks right.
 */
struct TemporalResult {
    int frames = 0;             // frames in the sequence
    int pairs = 0;              // consecutive pairs, frames − 1 (0 with fewer than 2 frames)
    size_t regionPixels = 0;    // pixels in the region (the whole image without a mask)
    size_t samples = 0;         // (pixel, pair) samples pooled
    size_t skippedPixels = 0;   // (pixel, pair) samples left out: non-finite in any input
    double level = kNaN;        // mean Y of the reference, all frames, finite region pixels
    double meanAbs = kNaN;      // mean d (absolute, linear luminance)
    double instability = kNaN;  // meanAbs / level: "temporal_instability" (dimensionless)
    double p95 = kNaN;          // 95th percentile (nearest rank) of d / level
    double noiseFloor = kNaN;   // mean of s·sqrt(2/π) / level; NaN without stderr images
    double debiased = kNaN;     // max(0, instability − noiseFloor); NaN without stderr images
    std::string note;           // why a value is NaN (and other caveats); empty if none
    /**
     * 1 channel, full size: per pixel, the mean of d over its pooled pairs (absolute, linear
     * luminance). Computed for every pixel (the mask only restricts the pooling); NaN where no
     * pair is finite. Empty with fewer than 2 frames.
     */
    Image map;
};

/**
 * test[k] and reference[k] are frame k of the technique and of the reference (3 or 4 channels,
 * a 4th is ignored, all one size). referenceStdError, if given, holds each reference frame's
 * per-pixel, per-channel standard error of the mean (one per frame, same size). Throws
 * gilab::Error naming the frame on a null image, a size or channel mismatch, or sequences of
 * different lengths. Fewer than 2 frames: pairs = 0, every value NaN (not an error).
 */
TemporalResult computeTemporalInstability(
    const std::vector<const Image*>& test, const std::vector<const Image*>& reference,
    const std::vector<const Image*>* referenceStdError = nullptr, const Mask* mask = nullptr);

/** snake_case keys, without the map; non-finite numbers are written as null. */
nlohmann::ordered_json toJson(const TemporalResult& result);

/**
 * The map of a TemporalResult as a magma PNG, normalised like the relMSE map: each pixel is
 * d / (fullScale · level), clamped to [0, 1] (1 = a mean change error of fullScale times the
 * reference's level). Where the level is not positive, the map's largest finite value is 1.
 * NaN pixels are magenta.
 */
void writeTemporalMapPng(const std::string& path, const TemporalResult& result,
                         double fullScale = 1.0);

}  // namespace gilab::metrics
