#pragma once
/** GPU mirrors shared by the dvs passes (shaders/common/voxel_cone.glsl ConeTraceParams). */
#include <glm/glm.hpp>

#include "core/voxel/voxel_grid.h"

namespace gilab {

/** Mirrors ConeTraceParams in shaders/common/voxel_cone.glsl. */
struct GpuConeTraceParams {
    glm::vec4 gridMinV0;    // xyz grid minimum corner, w v0
    glm::vec4 gridMaxStep;  // xyz grid maximum corner, w step factor (E10 beta)
    glm::vec4 distances;    // x max distance, y start offset t0 (world), z opacity cutoff,
                            // w AO lambda (1/world)
    glm::vec4 misc;         // x lod bias (radius level), y lift factor (0 = off), z lift rule
};
static_assert(sizeof(GpuConeTraceParams) == 64);

inline GpuConeTraceParams makeConeTraceParams(const VoxelGrid& grid, float stepFactor,
                                              float maxDistanceWorld, float startWorld,
                                              float opacityCutoff, float aoLambda, float lodBias,
                                              float lift, bool liftBlend) {
    GpuConeTraceParams p;
    p.gridMinV0 = glm::vec4(grid.origin(), grid.voxelSize());
    p.gridMaxStep = glm::vec4(grid.origin() + glm::vec3(grid.side()), stepFactor);
    p.distances = glm::vec4(maxDistanceWorld, startWorld, opacityCutoff, aoLambda);
    p.misc = glm::vec4(lodBias, lift, liftBlend ? 1.0f : 0.0f, 0.0f);
    return p;
}

}  // namespace gilab
