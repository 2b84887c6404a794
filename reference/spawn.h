#pragma once
/**
 * Where a ray leaves a surface point: a float origin in free space, on the side the path is on
 * of every triangle that could otherwise catch it, by margins that bound the floating-point
 * error of the point and of Embree's intersection test, not by a step that grows with the
 * distance from the world origin (docs/reference.md, "Ray origins"; renderer version 5).
 *
 * - The hit point is the exact intersection of the float ray with the float triangle's plane,
 *   computed in double and rounded once (pbrt-v4 bounds the interpolated point's error from
 *   its vertex magnitudes and barycentrics instead; here the one rounding is the only error).
 * - Embree decides whether a ray from O meets triangle T from v_k - O, rounded to float, and a
 *   normal built from those differences (its Plücker test): the plane distance it sees is off
 *   by about eps · L · (1 + L·l / (2 area)), L = max_k |v_k - O|, l = T's longest edge. A
 *   point at least that far (× 8) on its side of T's plane is never caught by T at t >= 0.
 *   The margin scales with T's size and its distance from O, never with |O|: a metre-sized
 *   room 5 km out gets the margins it gets at the origin (the point's own float steps of
 *   0.5 mm then dominate), and a 5 km ground quad gets millimetres.
 * - Every triangle within its margin of the point constrains the origin: the hit triangle,
 *   coplanar duplicates, and the neighbour across a concave edge or a contact (renderer
 *   version 4 stepped back along the arriving ray by 2^-13 of the triangle's largest
 *   coordinate instead: 0.6 m at 5 km). The side is the one the arriving ray (or the
 *   receiver, for a light sample) lies on. The constraints are met by projecting onto each
 *   violated half-space in turn, then rounding to float and nudging by ulps until every
 *   margin holds, measured in double on the float result.
 * - The candidates come from a list per triangle, built once: every triangle that comes
 *   within reach of it (15 on average on Sponza and Sibenik; an Embree point query per hit
 *   instead cost 1.8x the render). A triangle with more than kMaxNeighbours (a ground plane
 *   under a city) asks Embree's point query at each of its hits instead.
 */
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "reference/embree_scene.h"

namespace gilab::ref {

/** The point where the ray o + t d meets `tri`'s plane, in double; Embree's barycentric point
 *  (b1, b2) when the ray runs within 1e-4 of the plane (the intersection is ill-conditioned). */
glm::dvec3 exactHitPoint(const MeshTriangle& tri, const glm::vec3& o, const glm::vec3& d, float b1,
                         float b2);

/** The plane distance by which Embree's test of `tri` from `o` may be wrong (see above). */
double intersectionMargin(const MeshTriangle& tri, const glm::dvec3& o);

class SpawnOffsets {
public:
    explicit SpawnOffsets(const EmbreeScene& mesh);

    /** A float origin near p (a point of triangle `prim`) that every triangle within its
     *  margin of p has on the side of `toward` (a direction out of the surface: -ray
     *  direction, or towards a receiver). */
    glm::vec3 origin(const glm::dvec3& p, uint32_t prim, const glm::vec3& toward) const;

    /** The largest margin any triangle can ask for near itself. */
    double largestMargin() const { return m_largestMargin; }
    /** The triangles listed as within reach of `prim` (itself excluded); for tests. */
    size_t neighbourCount(uint32_t prim) const;
    /** Those of them that reach its inside, away from its edges (contacts, overlaps). */
    size_t interiorNeighbourCount(uint32_t prim) const;

    static constexpr size_t kMaxNeighbours = 256;
    struct Candidates;  // the constraints gathered for one origin

private:
    /** A listed neighbour: the box holding every point of the listing triangle within reach
     *  of it (the neighbour clipped to the slab of that reach around the triangle's plane,
     *  widened by the reach and rounded outwards). Its x range is also kept apart, packed, so
     *  that most entries are dismissed after reading 8 bytes. */
    struct Neighbour {
        glm::vec3 lo, hi;
        uint32_t prim;
    };
    void buildNeighbours();

    const EmbreeScene& m_mesh;
    std::vector<double> m_reach;  // per triangle: 2 x its largest margin near itself + slack
    /** What a hit on a triangle reads first: one 16-byte record. */
    struct TriangleInfo {
        uint32_t first = 0;         // its neighbours are m_neighbours[first, first + count)
        uint16_t count = 0;         // kOverflow: more than kMaxNeighbours, Embree's query instead
        uint16_t interior = 0;      // the first `interior` of them reach its inside
        float inset = 0.0f;         // a hit this far inside every edge sees the interior ones only
        float edgeOverArea = 0.0f;  // longest edge / (2 x area), for its own margin
    };
    static constexpr uint16_t kOverflow = 0xffff;
    std::vector<TriangleInfo> m_info;
    std::vector<Neighbour> m_neighbours;  // per triangle, those reaching its inside first
    std::vector<glm::vec2> m_xRange;      // m_neighbours[i].lo.x, hi.x
    double m_largestMargin = 0.0;
    double m_slack = 0.0;  // the scene's float spacing at its largest coordinate, x 4
};

}  // namespace gilab::ref
