#pragma once
/**
 * Why a point or spot light's shadow leaks (issue 43 item 5): each pixel where the rasteriser
 * puts light that the path tracer has at 0 is classified with Embree rays, weighted by its
 * leaked luminance. The shadow map is modelled as what it is: one depth per texel, taken along
 * the texel's ray from the light, compared with the receiver's distance minus a bias.
 *
 *   background     the camera ray through the pixel centre meets nothing
 *   back-facing    the side of the surface the camera sees faces away from the light (its
 *                  geometric normal; the raster's interpolated shading normal may still face it)
 *   not occluded   the path tracer's shadow ray (from its spawn origin, reference/spawn.h) is
 *                  clear: the reference is 0 for another reason (the shading normal faces away,
 *                  outside a spot's cone, a black texel)
 *   near plane     the occluder is closer to the light than the maps' near plane
 *   contact        the occluder is within the bias margin of the receiver
 *                  ((constant bias + 1) texels at the receiver): no depth map can separate them
 *   texel edge     some but not all of 3 x 3 rays spread over one texel's solid angle around the
 *                  receiver's direction meet an occluder before the receiver's margin: an
 *                  occluder's outline (or all of an occluder thinner than a texel) crosses the
 *                  receiver's texel, and the map's one depth per texel may miss it
 *   unexplained    all 9 rays meet the occluder: an occluder the map should hold
 */
#include <cstddef>
#include <string>

#include "core/image/image.h"
#include "core/scene/scene.h"

namespace gilab::cli {

struct LeakCauses {
    double total = 0.0;  // leaked luminance summed over the leaking pixels
    double background = 0.0, backFacing = 0.0, notOccluded = 0.0, nearPlane = 0.0, contact = 0.0,
           texelEdge = 0.0, unexplained = 0.0;
    size_t pixels = 0;
};

/** The map geometry a lookup sees for one light (shadow_maps.h). */
struct ShadowModel {
    uint32_t resolution = 1024;  // texels per side of a cube face or a spot map
    float constantBias = 0.5f;   // texels
};

/** Classifies the leaks of `raster` (emission + direct, linear RGB) against `reference` for
 *  `scene` lit by its first light, which must be a point or spot light (else gilab::Error). */
LeakCauses classifyLeaks(const Scene& scene, const Image& raster, const Image& reference,
                         const ShadowModel& model);

/** "contact 71 %, unexplained 29 % (17 px)" (shares of the leaked luminance, largest first). */
std::string describeLeakCauses(const LeakCauses& causes);

}  // namespace gilab::cli
