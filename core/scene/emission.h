#pragma once
/**
 * The radiance an emissive triangle sends out, averaged over the triangle: the one definition
 * the rasteriser's exact area-light irradiance, its emitter samples' allocation and the path
 * tracer's light selection share (docs/shared_passes.md, "Area lights").
 */
#include <cstddef>

#include <glm/glm.hpp>

#include "core/scene/scene.h"

namespace gilab {

/** The texture at uv, bilinear at mip 0 as the path tracer filters it (texel centres at
 *  (i + 0.5) / size, the texture's wrap modes, sRGB decoded per texel before the weights). */
glm::vec3 bilinearLinear(const Texture& tex, glm::vec2 uv);

/**
 * Mean emitted radiance of triangle t (W/(m^2 sr)): its material's emissive factor times the
 * mean of its emissive texture over the triangle's uv footprint. The mean is the average of the
 * bilinear texture at the centroids of the triangle cut into k^2 equal triangles, with about
 * four points per texel the footprint covers (k^2 between 64 and 65,536): exact for a texture
 * that is linear over each piece, and the footprint's mean to a fraction of a texel elsewhere.
 * (Until 2026-12 the whole texture's mean was used for every triangle of the material.)
 */
glm::vec3 meanTriangleEmission(const Scene& scene, size_t t);

/** The emissive triangles of a scene as a whole (`gilab scene-info`). */
struct EmitterSummary {
    size_t triangleCount = 0;  // triangles whose material emits
    double areaM2 = 0.0;       // their area, one side
    glm::dvec3 powerW{0.0};    // emitted power: sum of pi x mean Le x area x sides (1, or 2
                               // for a double-sided material); a Lambertian emitter
};
EmitterSummary computeEmitterSummary(const Scene& scene);

}  // namespace gilab
