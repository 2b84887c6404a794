#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include <OpenImageIO/imageio.h>

#include "core/image/atomic_write.h"
#include "core/image/color.h"
#include "core/image/image_io.h"
#include "core/util/error.h"

namespace gilab {

namespace {

float applyCurve(float x, ToneMap::Curve curve) {
    switch (curve) {
        case ToneMap::Curve::Aces:
            return acesNarkowicz(x);
        case ToneMap::Curve::Clamp:
            break;
    }
    return std::clamp(x, 0.0f, 1.0f);
}

}  // namespace

Image tonemapToSrgb(const Image& linearRgb, const ToneMap& tm) {
    const int channels = linearRgb.channels();
    if (channels != 1 && channels != 3 && channels != 4) {
        throw Error("tonemapToSrgb: expected 1, 3 or 4 channels, got " + std::to_string(channels));
    }
    if (!std::isfinite(tm.exposureEv)) throw Error("tonemapToSrgb: exposure is not finite");
    const float scale = std::exp2(tm.exposureEv);
    Image out(linearRgb.width(), linearRgb.height(), 3);
    const size_t pixels = linearRgb.pixelCount();
    const float* src = linearRgb.data();
    float* dst = out.data();
    for (size_t p = 0; p < pixels; ++p) {
        float rgb[3];
        bool finite = true;
        for (int c = 0; c < 3; ++c) {
            rgb[c] = src[p * size_t(channels) + size_t(channels == 1 ? 0 : c)];
            finite = finite && std::isfinite(rgb[c]);
        }
        if (!finite) {
            // NaN/Inf is written as magenta so a broken pixel is never hidden by the curve.
            dst[p * 3 + 0] = 1.0f;
            dst[p * 3 + 1] = 0.0f;
            dst[p * 3 + 2] = 1.0f;
            continue;
        }
        for (int c = 0; c < 3; ++c) {
            // Negative radiance clamps to 0 before the curve; overflow after scaling is > 1.
            float scaled = std::max(rgb[c], 0.0f) * scale;
            dst[p * 3 + size_t(c)] =
                std::clamp(linearToSrgb(applyCurve(scaled, tm.curve)), 0.0f, 1.0f);
        }
    }
    return out;
}

void writePngTonemapped(const std::string& path, const Image& linearRgb, const ToneMap& tm) {
    if (linearRgb.empty()) throw Error(path + ": cannot write an empty image");
    Image srgb;
    try {
        srgb = tonemapToSrgb(linearRgb, tm);
    } catch (const Error& e) {
        throw Error(path + ": " + e.what());
    }
    std::vector<uint8_t> bytes(srgb.values().size());
    for (size_t i = 0; i < bytes.size(); ++i) {
        bytes[i] = uint8_t(std::lround(srgb.values()[i] * 255.0f));  // round to nearest
    }
    OIIO::ImageSpec spec(srgb.width(), srgb.height(), 3, OIIO::TypeDesc::UINT8);
    spec.attribute("oiio:ColorSpace", "sRGB");
    detail::writeImageAtomic(path, "png", spec, bytes.data());
}

}  // namespace gilab
