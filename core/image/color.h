#pragma once
/**
 * Colour maths used across the project: the sRGB transfer functions, Rec.709 luminance and the
 * tonemapping curves. Linear values are Rec.709/sRGB primaries (docs/conventions.md).
 */
#include <algorithm>
#include <cmath>

#include <glm/glm.hpp>

namespace gilab {

/** Rec.709 / sRGB relative luminance weights. */
inline constexpr float kLuminanceR = 0.2126f;
inline constexpr float kLuminanceG = 0.7152f;
inline constexpr float kLuminanceB = 0.0722f;

inline float luminance(float r, float g, float b) {
    return kLuminanceR * r + kLuminanceG * g + kLuminanceB * b;
}
inline float luminance(const glm::vec3& rgb) {
    return luminance(rgb.r, rgb.g, rgb.b);
}

/** Exact sRGB OETF (IEC 61966-2-1), linear -> encoded; piecewise, no gamma-2.2 shortcut. */
inline float linearToSrgb(float linear) {
    if (linear <= 0.0031308f) return 12.92f * linear;
    return 1.055f * std::pow(linear, 1.0f / 2.4f) - 0.055f;
}

/** Exact inverse of linearToSrgb, encoded -> linear. */
inline float srgbToLinear(float encoded) {
    if (encoded <= 0.04045f) return encoded / 12.92f;
    return std::pow((encoded + 0.055f) / 1.055f, 2.4f);
}

/**
 * ACES filmic curve fit by Krzysztof Narkowicz, "ACES Filmic Tone Mapping Curve" (2015):
 * x (2.51 x + 0.03) / (x (2.43 x + 0.59) + 0.14), saturated to [0, 1]. Applied per channel
 * as published, with no extra exposure pre-scale. Negative input gives 0.
 */
inline float acesNarkowicz(float x) {
    // Beyond ~1e4 the curve has saturated; bounding x keeps x*x finite for huge inputs.
    double v = std::clamp(double(x), 0.0, 1.0e4);
    double mapped = (v * (2.51 * v + 0.03)) / (v * (2.43 * v + 0.59) + 0.14);
    return float(std::clamp(mapped, 0.0, 1.0));
}

}  // namespace gilab
