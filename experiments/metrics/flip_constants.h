#pragma once
/**
 * Every constant of the two FLIP papers, in one place. Citations:
 *   [FLIP20] P. Andersson, J. Nilsson, T. Akenine-Möller, M. Oskarsson, K. Åström,
 *            M. D. Fairchild, "FLIP: A Difference Evaluator for Alternating Images",
 *            Proc. ACM Comput. Graph. Interact. Tech. 3(2), 2020 (HPG 2020).
 *   [FLIP21] P. Andersson, J. Nilsson, P. Shirley, T. Akenine-Möller, "Visualizing Errors in
 *            Rendered High Dynamic Range Images", Eurographics 2021 short papers.
 * Sections are named by their titles in the papers. docs/metrics.md restates all of them.
 */

namespace gilab::metrics::flip {

inline constexpr double kPi = 3.14159265358979323846;

// --- [FLIP20] colour pipeline: colour spaces -----------------------------------------------
// Linear sRGB (Rec.709 primaries, D65) -> CIE XYZ (IEC 61966-2-1). The reference white
// (Xn, Yn, Zn) is the image of RGB = (1, 1, 1), i.e. the row sums.
inline constexpr double kRgbToXyz[3][3] = {{0.4124564, 0.3575761, 0.1804375},
                                           {0.2126729, 0.7151522, 0.0721750},
                                           {0.0193339, 0.1191920, 0.9503041}};
// YCxCz opponent space (Zhang & Wandell's S-CIELAB, linearised, as [FLIP20] uses it):
//   Y = 116 Y/Yn − 16, Cx = 500 (X/Xn − Y/Yn), Cz = 200 (Y/Yn − Z/Zn).
inline constexpr double kYccLightnessScale = 116.0;
inline constexpr double kYccLightnessOffset = 16.0;
inline constexpr double kYccCxScale = 500.0;
inline constexpr double kYccCzScale = 200.0;
// CIELAB uses the same 116/16, 500, 200 and the cube root with the linear toe below δ³,
// δ = 6/29 (CIE 15:2004).
inline constexpr double kLabDelta = 6.0 / 29.0;

// --- [FLIP20] colour pipeline: spatial filtering ---------------------------------------------
// Contrast sensitivity functions as sums of Gaussians in frequency f [cycles/degree],
// CSF(f) = a1 exp(−b1 f²) + a2 exp(−b2 f²), whose spatial filters are
// S(x) = a1 sqrt(π/b1) exp(−π² x²/b1) + a2 sqrt(π/b2) exp(−π² x²/b2), x in degrees.
struct Csf {
    double a1, b1, a2, b2;
};
inline constexpr Csf kCsfAchromatic{1.0, 0.0047, 0.0, 1.0e-5};  // Y channel
inline constexpr Csf kCsfRedGreen{1.0, 0.0053, 0.0, 1.0e-5};    // Cx channel
inline constexpr Csf kCsfBlueYellow{34.1, 0.04, 13.5, 0.025};   // Cz channel
// One filter radius for all three channels: 3 standard deviations of the widest Gaussian,
// σ = sqrt(b_max / (2π²)) degrees, r = ceil(3 σ ppd) pixels. Each filter sums to 1.
inline constexpr double kCsfBMax = 0.04;
inline constexpr double kCsfRadiusSigmas = 3.0;

// --- [FLIP20] colour pipeline: Hunt effect and colour metric ----------------------------------
// Hunt adjustment: a* and b* are scaled by 0.01 L*.
inline constexpr double kHuntScale = 0.01;
// HyAB distance |ΔL| + ||(Δa, Δb)||, raised to q_c (perceptual compression).
inline constexpr double kColorExponent = 0.7;  // q_c
// Mapping to [0, 1]: errors below p_c · cmax are mapped linearly to [0, p_t], the rest
// linearly to [p_t, 1]; cmax = (HyAB between Hunt-adjusted pure green and pure blue)^q_c.
inline constexpr double kColorCutoffFraction = 0.4;  // p_c
inline constexpr double kColorCutoffValue = 0.95;    // p_t

// --- [FLIP20] feature pipeline ---------------------------------------------------------------
// Edge (first derivative) and point (second derivative) detectors: Gaussian derivatives with
// σ = ½ w ppd pixels, w = 0.082 degrees, radius ceil(3 σ); each filter's positive weights sum
// to 1 and its negative weights to −1. Input: the achromatic channel (Y + 16)/116 = Y/Yn.
inline constexpr double kFeatureWidthDeg = 0.082;  // w
inline constexpr double kFeatureRadiusSigmas = 3.0;
// ΔE_f = (max(|‖e_r‖ − ‖e_t‖|, |‖p_r‖ − ‖p_t‖|) / sqrt 2)^q_f
inline constexpr double kFeatureExponent = 0.5;  // q_f
// Final: ΔE = ΔE_c^(1 − ΔE_f).

// --- [FLIP21] §2.1 tone mapper and exposure range -------------------------------------------
// t(x) = (a x² + b x) / (c x² + d x + e): Narkowicz's ACES fit including its 0.6 pre-scale.
inline constexpr double kAcesA = 0.6 * 0.6 * 2.51;
inline constexpr double kAcesB = 0.6 * 0.03;
inline constexpr double kAcesC = 0.6 * 0.6 * 2.43;
inline constexpr double kAcesD = 0.6 * 0.59;
inline constexpr double kAcesE = 0.14;
// c_start = log2(t⁻¹(0.85) / Y_max), c_stop = log2(t⁻¹(0.85) / Y_median) of the reference's
// luminance; N = max(2, ceil(c_stop − c_start)) exposures, evenly spaced, both ends included.
inline constexpr double kExposureTarget = 0.85;
inline constexpr int kMinExposureCount = 2;

}  // namespace gilab::metrics::flip
