// The magma colour map (S. van der Walt, N. Smith, matplotlib 1.5, 2015), the map the FLIP
// papers use for error maps. A 256-entry lookup table is generated at first use by linear
// interpolation (in sRGB) between 17 anchor colours of the published map, at entries
// 0, 16, 32, ..., 240 and 255 of its 256; values are indexed by round(255 t) as in FLIP.
#include <algorithm>
#include <array>
#include <cmath>

#include "core/image/color.h"
#include "core/util/error.h"
#include "experiments/metrics/metrics.h"

namespace gilab::metrics {

namespace {

struct Anchor {
    int index;  // entry of the 256-entry map
    float rgb[3];
};

// Anchor colours (sRGB-encoded) of the published magma map at every 16th entry and the last;
// linear interpolation between them reproduces the full map to within 0.01 per channel.
constexpr Anchor kMagmaAnchors[] = {
    {0, {0.001462f, 0.000466f, 0.013866f}},  // near-black purple
    {16, {0.039608f, 0.031090f, 0.133515f}},
    {32, {0.113094f, 0.065492f, 0.276784f}},
    {48, {0.211718f, 0.061992f, 0.418647f}},
    {64, {0.316654f, 0.071690f, 0.485380f}},  // purple
    {80, {0.414709f, 0.110431f, 0.504662f}},
    {96, {0.512831f, 0.148179f, 0.507648f}},
    {112, {0.613617f, 0.181811f, 0.498536f}},
    {128, {0.716387f, 0.214982f, 0.475290f}},  // magenta-red
    {144, {0.816914f, 0.255895f, 0.436461f}},
    {160, {0.904281f, 0.319610f, 0.388137f}},
    {176, {0.960949f, 0.418323f, 0.359630f}},
    {192, {0.986700f, 0.535582f, 0.382210f}},  // orange
    {208, {0.996096f, 0.653659f, 0.446213f}},
    {224, {0.996898f, 0.769591f, 0.534892f}},
    {240, {0.992440f, 0.884330f, 0.640099f}},
    {255, {0.987053f, 0.991438f, 0.749504f}},  // light yellow
};

using Table = std::array<std::array<float, 3>, 256>;

const Table& magmaTable() {
    static const Table table = [] {
        Table t{};
        constexpr size_t anchorCount = sizeof(kMagmaAnchors) / sizeof(kMagmaAnchors[0]);
        for (size_t a = 0; a + 1 < anchorCount; ++a) {
            const Anchor& lo = kMagmaAnchors[a];
            const Anchor& hi = kMagmaAnchors[a + 1];
            for (int i = lo.index; i <= hi.index; ++i) {
                const float f = float(i - lo.index) / float(hi.index - lo.index);
                for (int c = 0; c < 3; ++c) {
                    t[size_t(i)][size_t(c)] = lo.rgb[c] + f * (hi.rgb[c] - lo.rgb[c]);
                }
            }
        }
        return t;
    }();
    return table;
}

}  // namespace

void getMagmaSrgb(double t, float rgb[3]) {
    const double clamped = std::isfinite(t) ? std::clamp(t, 0.0, 1.0) : 0.0;
    const auto& entry = magmaTable()[size_t(std::lround(clamped * 255.0))];
    for (int c = 0; c < 3; ++c)
        rgb[c] = entry[size_t(c)];
}

Image magmaColorize(const Image& errorMap) {
    if (errorMap.channels() != 1) {
        throw Error("magmaColorize: expected a 1-channel error map, got " +
                    std::to_string(errorMap.channels()) + " channels");
    }
    Image out(errorMap.width(), errorMap.height(), 3);
    for (size_t p = 0; p < errorMap.pixelCount(); ++p) {
        const float v = errorMap.data()[p];
        float* dst = out.data() + p * 3;
        if (!std::isfinite(v)) {
            dst[0] = dst[1] = dst[2] = v;  // the PNG writer paints it magenta
            continue;
        }
        float srgb[3];
        getMagmaSrgb(v, srgb);
        // Linear values whose sRGB encoding is the magma colour.
        for (int c = 0; c < 3; ++c)
            dst[c] = srgbToLinear(srgb[c]);
    }
    return out;
}

void writeMagmaPng(const std::string& path, const Image& errorMap) {
    writePngTonemapped(path, magmaColorize(errorMap), ToneMap{});
}

}  // namespace gilab::metrics
