#pragma once
/**
 * The same-VPL reference of a VPL technique's run (Noël & Biri 2014, Table II; docs/vpl.md):
 * the technique's last-frame VPLs shaded on the CPU with exact Embree shadow rays
 * (reference/vpl_reference.h) and without any visibility. Enabled per experiment with
 * "metrics": {"same_vpl_reference": true}.
 *
 * Table II compares three images with the reference R = emission + direct + exact VPL light:
 *   direct_only   emission + direct
 *   unshadowed    emission + direct + the same VPLs with V = 1
 *   method        the technique's final image
 * each by its MSE on linear HDR values and on 8-bit sRGB (0-255, the run's tonemap), the
 * paper's probable scale. The indirect layers are compared too (relMSE, energy ratios).
 */
#include <vector>

#include <nlohmann/json.hpp>

#include "core/image/image.h"
#include "core/image/image_io.h"

namespace gilab {
class FrameHarness;
struct Scene;

namespace exp {

/**
 * Null when the technique has no VPL set; else the Table II numbers. Appends the layers
 * "vpl_exact" and "vpl_unshadowed" (indirect radiance) to `layers`.
 */
nlohmann::ordered_json computeSameVplReference(FrameHarness& harness, const Scene& scene,
                                               std::vector<ImageLayer>& layers,
                                               const ToneMap& tonemap);

}  // namespace exp
}  // namespace gilab
