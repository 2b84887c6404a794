#pragma once
/**
 * Random numbers and sample warps of the reference path tracer.
 *
 * Every random number is a pure function of (seed, pixel, sample index, dimension): a
 * counter-based hash, so a sample is the same whichever thread renders it and whenever it is
 * rendered (docs/reference.md, "Determinism"). The numbers are independent uniform variates,
 * not a low-discrepancy sequence: the per-pixel standard errors the Accumulator reports assume
 * i.i.d. samples, which stratified or QMC points would break.
 */
#include <bit>
#include <cmath>
#include <cstdint>

#include <glm/glm.hpp>

namespace gilab::ref {

inline constexpr float kPi = 3.14159265358979323846f;
inline constexpr float kInvPi = 0.31830988618379067154f;

/** 64-bit finaliser of SplitMix64 (Steele, Lea, Flood 2014; Stafford's "Mix13" constants). */
inline uint64_t mix64(uint64_t x) {
    x ^= x >> 30;
    x *= 0xbf58476d1ce4e5b9ull;
    x ^= x >> 27;
    x *= 0x94d049bb133111ebull;
    x ^= x >> 31;
    return x;
}

/** The uniform float in [0, 1) made of the top 24 bits of a hash. */
inline float toUnitFloat(uint64_t h) {
    return float(uint32_t(h >> 40)) * 0x1p-24f;
}

/**
 * Counter-based sampler of one (seed, pixel, sample): dimension d gives
 * mix64(key ^ (d + 1) * golden), key = mix64(mix64(mix64(seed) ^ pixel) ^ sample).
 * Dimensions are consumed in a fixed order along the path, so the stream is reproducible.
 */
class Sampler {
public:
    Sampler() = default;
    Sampler(uint64_t seed, uint64_t pixel, uint64_t sampleIndex)
        : m_key(mix64(mix64(mix64(seed + 0x632be59bd9b4e019ull) ^ pixel) ^ sampleIndex)) {}

    float get1D() { return toUnitFloat(mix64(m_key ^ (uint64_t(++m_dimension) * kGolden))); }
    /** 53-bit uniform in [0, 1), for choices among millions of items (light selection). */
    double get1DDouble() {
        return double(mix64(m_key ^ (uint64_t(++m_dimension) * kGolden)) >> 11) * 0x1p-53;
    }
    glm::vec2 get2D() {
        const float a = get1D();
        return {a, get1D()};
    }
    uint32_t dimension() const { return m_dimension; }

private:
    static constexpr uint64_t kGolden = 0x9e3779b97f4a7c15ull;
    uint64_t m_key = 0;
    uint32_t m_dimension = 0;
};

/** Orthonormal basis around a unit z axis (Duff et al. 2017, "Building an Orthonormal Basis,
 *  Revisited"). */
struct Frame {
    glm::vec3 s, t, n;

    static Frame fromZ(const glm::vec3& n) {
        const float sign = std::copysign(1.0f, n.z);
        const float a = -1.0f / (sign + n.z);
        const float b = n.x * n.y * a;
        return {glm::vec3(1.0f + sign * n.x * n.x * a, sign * b, -sign * n.x),
                glm::vec3(b, sign + n.y * n.y * a, -n.y), n};
    }
    glm::vec3 toLocal(const glm::vec3& v) const {
        return {glm::dot(v, s), glm::dot(v, t), glm::dot(v, n)};
    }
    glm::vec3 toWorld(const glm::vec3& v) const { return v.x * s + v.y * t + v.z * n; }
};

/** Shirley & Chiu 1997 concentric map of [0,1)^2 onto the unit disk. */
inline glm::vec2 sampleConcentricDisk(glm::vec2 u) {
    const glm::vec2 o = 2.0f * u - 1.0f;
    if (o.x == 0.0f && o.y == 0.0f) return glm::vec2(0.0f);
    float r, theta;
    if (std::abs(o.x) > std::abs(o.y)) {
        r = o.x;
        theta = 0.25f * kPi * (o.y / o.x);
    } else {
        r = o.y;
        theta = 0.5f * kPi - 0.25f * kPi * (o.x / o.y);
    }
    return r * glm::vec2(std::cos(theta), std::sin(theta));
}

/** Cosine-weighted direction about +z (Malley's method); pdf = cos(theta) / pi. */
inline glm::vec3 sampleCosineHemisphere(glm::vec2 u) {
    const glm::vec2 d = sampleConcentricDisk(u);
    const float z = std::sqrt(std::max(0.0f, 1.0f - d.x * d.x - d.y * d.y));
    return {d.x, d.y, z};
}

/** Uniform direction on the unit sphere; pdf = 1 / (4 pi). */
inline glm::vec3 sampleUniformSphere(glm::vec2 u) {
    const float z = 1.0f - 2.0f * u.x;
    const float r = std::sqrt(std::max(0.0f, 1.0f - z * z));
    const float phi = 2.0f * kPi * u.y;
    return {r * std::cos(phi), r * std::sin(phi), z};
}

/** Uniform barycentrics (b1, b2) on a triangle (pbrt-v3 §13.6.5: sqrt warp); pdf = 1 / area. */
inline glm::vec2 sampleUniformTriangle(glm::vec2 u) {
    const float su = std::sqrt(u.x);
    return {1.0f - su, u.y * su};
}

/** Veach 1997 §9.2.4 power heuristic (beta = 2) for the technique with pdf fPdf against gPdf;
 *  written as 1 / (1 + (g/f)^2) so huge or infinite pdfs stay finite. */
inline float powerHeuristic(float fPdf, float gPdf) {
    if (!(fPdf > 0.0f)) return 0.0f;
    const float r = gPdf / fPdf;
    return 1.0f / (1.0f + r * r);
}

/**
 * Moves a point off a surface along the (unit, geometric) normal n by a few hundred ulps of its
 * coordinates, so the offset scales with |p| (Waechter & Binder, "A Fast and Robust Method for
 * Avoiding Self-Intersection", Ray Tracing Gems 2019, ch. 6). Rays then start at t = 0.
 * Near the origin (|p| < originScale / 32) ulps vanish and a fixed step of originScale / 65536
 * is used instead. The chapter's constants assume a scene of about unit size; `originScale` =
 * min(1, the scene's largest coordinate magnitude) (rayOffsetScale) shrinks that step with a
 * scene smaller than a metre: a 1 mm box otherwise gets offsets of 3 % of its size and a biased
 * image (docs/reference.md "Ray offsets", found by `gilab audit`).
 */
inline glm::vec3 offsetRayOrigin(const glm::vec3& p, const glm::vec3& n, float originScale = 1.0f) {
    const float kOrigin = originScale / 32.0f;
    const float kFloatScale = originScale / 65536.0f;
    constexpr float kIntScale = 256.0f;
    glm::vec3 out;
    for (int i = 0; i < 3; ++i) {
        const int32_t ofs = int32_t(kIntScale * n[i]);
        const int32_t bits = std::bit_cast<int32_t>(p[i]) + (p[i] < 0.0f ? -ofs : ofs);
        out[i] = std::abs(p[i]) < kOrigin ? p[i] + kFloatScale * n[i] : std::bit_cast<float>(bits);
    }
    return out;
}

/** offsetRayOrigin's originScale for a scene with these bounds: min(1, max |coordinate|). */
inline float rayOffsetScale(const glm::vec3& lo, const glm::vec3& hi) {
    const glm::vec3 m = glm::max(glm::abs(lo), glm::abs(hi));
    const float magnitude = std::max(m.x, std::max(m.y, m.z));
    return std::isfinite(magnitude) && magnitude > 0.0f ? std::min(1.0f, magnitude) : 1.0f;
}

inline bool isFinite(const glm::vec3& v) {
    return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

inline float maxComponent(const glm::vec3& v) {
    return std::max(v.x, std::max(v.y, v.z));
}

}  // namespace gilab::ref
