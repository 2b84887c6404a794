#pragma once
/**
 * Debug export of a scene topology (techniques/topovpl/scene_topology.h) as one self-contained
 * glTF 2.0 file (buffers embedded) that any viewer opens:
 *   mesh "skeleton"  LINES: the segmented skeleton's edges, each vertex coloured by its cluster
 *   mesh "nodes"     POINTS: the kept nodes (topology, curvature, coverage), cluster colours
 *   mesh "gates"     TRIANGLES: every visibility gate as a disk (24 segments), coloured by the
 *                    first of its two clusters
 * World units, the scene's own frame. Throws gilab::Error naming the file when it cannot write.
 */
#include <string>
#include <vector>

#include <glm/glm.hpp>

namespace gilab::topo {

struct SceneTopology;

/** A stable colour for cluster c (shared by the export and the debug view). */
glm::vec3 clusterColour(uint32_t c);

/** gateRadii: the disks' radii, one per gate (the per-frame gate-radius rule); empty: each
 *  gate's `radius` (E4's min of the two end balls). */
void exportTopologyGltf(const SceneTopology& topology, const std::string& path,
                        const std::vector<float>& gateRadii = {});

}  // namespace gilab::topo
