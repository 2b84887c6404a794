#pragma once
/**
 * The power each punctual light puts into the scene, traced with Embree (issue 43's control for
 * what a voxel volume should hold): rays leave the light over its emission (a point light's
 * sphere, a spot's outer cone weighted by its falloff, a directional light's disk over the
 * scene's bounding sphere), each carrying its share of the flux, and the first surface each ray
 * meets receives it. Reflected power = sum of albedo x flux over those hits (base colour x
 * texture at the hit, mean of rgb), the light the first bounce starts from; it is what vct's
 * photons (`power_photons_reflected_w`) and cvgi's lit voxels (`lit_power_w`) should hold.
 * Emissive triangles are left out (they have no single flux to share).
 */
#include <cstdint>
#include <string>
#include <vector>

#include "core/scene/scene.h"

namespace gilab::ref {

struct LightPower {
    std::string light;        // the light's name or "light <i>"
    double emittedW = 0.0;    // mean of rgb: the flux the rays carry (4 pi I for a point light)
    double incidentW = 0.0;   // of which met a surface
    double reflectedW = 0.0;  // albedo x incident, summed over the hits
    uint64_t rays = 0;
};

/** One entry per punctual light, `rays` rays each (stratified, deterministic). */
std::vector<LightPower> punctualLightPower(const Scene& scene, uint32_t rays);

}  // namespace gilab::ref
