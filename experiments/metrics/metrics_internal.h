#pragma once
/** Helpers shared by the metric sources; not part of the public API (metrics.h). */
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/image/image.h"
#include "experiments/metrics/metrics.h"

namespace gilab::metrics::detail {

/** Throws gilab::Error unless both have 3 or 4 channels and the same non-zero size. */
void checkPair(const Image& test, const Image& reference, const char* what);
/** Throws unless the mask is empty (none) or the image's size. */
void checkMask(const Mask* mask, int width, int height, const char* what);
/** True if R, G and B of pixel p are finite. */
bool isFinitePixel(const Image& image, size_t p);

/**
 * Copies of test and reference (RGB only) in which every pixel that is non-finite in either is
 * replaced, in both, by the reference's value if finite, else 0: spatial filters then see no
 * error there and no NaN spreads. The pixel is left out of pooling by the PixelSelection.
 */
void makeFinitePair(const Image& test, const Image& reference, Image& testOut, Image& refOut);

/** Planar single-channel float image. */
struct Plane {
    int width = 0;
    int height = 0;
    std::vector<float> v;
    Plane() = default;
    Plane(int w, int h, float fill = 0.0f) : width(w), height(h), v(size_t(w) * h, fill) {}
};

/** 1D convolution along rows / columns, kernel of odd length 2r + 1, clamp-to-edge borders. */
void convolveRows(const Plane& src, Plane& dst, const std::vector<float>& kernel);
void convolveCols(const Plane& src, Plane& dst, const std::vector<float>& kernel);
/** Rows with kx, then columns with ky. */
Plane convolveSeparable(const Plane& src, const std::vector<float>& kx,
                        const std::vector<float>& ky);

// --- FLIP internals (flip_color.cpp, flip_features.cpp, flip.cpp) --------------------------

/** Linear RGB in [0, 1], planar. */
struct RgbPlanes {
    Plane r, g, b;
};
/** The CIELAB image after CSF filtering and the Hunt adjustment. */
struct HuntLab {
    Plane l, a, b;
};
HuntLab computeFilteredHuntLab(const RgbPlanes& linear, double ppd);
/** Per-pixel colour error ΔE_c in [0, 1] (HyAB^q_c, remapped with p_c, p_t). */
std::vector<float> computeColorError(const HuntLab& test, const HuntLab& ref);
/** cmax = HyAB(Hunt(Lab(green)), Hunt(Lab(blue)))^q_c. */
double getMaxColorError();
/** Hunt-adjusted CIELAB of one linear RGB colour (for tests and cmax). */
void linearRgbToHuntLab(double r, double g, double b, double lab[3]);

/** Per-pixel feature error ΔE_f in [0, 1]. */
std::vector<float> computeFeatureError(const RgbPlanes& test, const RgbPlanes& ref, double ppd);

/** LDR-FLIP map of linear [0, 1] RGB planes: ΔE_c^(1 − ΔE_f). */
std::vector<float> computeLdrFlipMap(const RgbPlanes& test, const RgbPlanes& ref, double ppd);
/** Linear RGB planes of an Image's RGB, each value scaled, tonemapped (optional) and clamped. */
RgbPlanes toPlanesSrgbDecoded(const Image& srgb01);
RgbPlanes toPlanesHdrToneMapped(const Image& linear, double exposureScale);

/** Standard normal deviates from a fixed seed (Box–Muller on splitmix64), platform-exact. */
class NormalRng {
public:
    explicit NormalRng(uint64_t seed) : m_state(seed) {}
    double next();

private:
    uint64_t nextU64();
    uint64_t m_state;
    bool m_hasSpare = false;
    double m_spare = 0.0;
};

/** A metric value for the JSON summaries: the number, or null when NaN/Inf. */
inline nlohmann::ordered_json number(double v) {
    return std::isfinite(v) ? nlohmann::ordered_json(v) : nlohmann::ordered_json(nullptr);
}

}  // namespace gilab::metrics::detail
