#pragma once
/**
 * Topology-preserving curve thinning of a voxel set, for the curvilinear skeleton of the empty
 * space that topological VPLs are placed on (Noël & Biri 2014).
 *
 * Algorithm: directional (6-subiteration: U, D, N, S, E, W) thinning with parallel candidate
 * marking and a sequential re-checked deletion, the scheme of Lee, Kashyap & Chu 1994 ("Building
 * skeleton models via 3-D medial surface/axis thinning algorithms", CVGIP: GMIP 56(6)), with
 * the full simple-point test of Bertrand & Malandain 1994 ("A new characterization of
 * three-dimensional simple points", PRL 15(2)) in place of LKC's connectivity-only re-check.
 * Object: 26-connectivity; background: 6-connectivity. In each subiteration of direction d:
 *   1. (parallel, TBB, read-only) mark the object voxels p whose d-neighbour is background, that
 *      are simple (T26(p, X) = 1 and T6(p, ~X) = 1) and are not curve ends;
 *   2. (sequential, ascending voxel index) delete each marked voxel that is STILL simple in the
 *      current, partly thinned set.
 * A curve end has exactly one object 26-neighbour, which itself has exactly two (the end of a
 * curve at least 3 voxels long); a tip stuck on a junction or a sheet is not one, so 1-voxel spurs
 * are thinned away (deviation from LKC's plain one-neighbour end point, which left spurs on a solid
 * torus). Passes of 6 subiterations repeat until one deletes nothing, in two phases:
 *   - phase 1 also asks the (-d)-neighbour of a candidate to be object (as in the directional
 *     templates of Palágyi & Kuba 1998, PRL 19(7)): a deleted point's (-d)-neighbour survives the
 *     subiteration, so a 2-thick bar is peeled layer by layer and not eaten along its length;
 *   - phase 2 drops that condition and re-checks the curve end at deletion, running to a fixpoint
 *     so that nothing removable is left.
 *
 * Guarantees:
 *   - Topology: every deletion removes a point simple in the current set, and deleting simple
 *     points one at a time preserves topology (Kong & Rosenfeld 1989, "Digital topology:
 * introduction and survey", CVGIP 48(3)): the number of 26-components, cavities and tunnels (so the
 * Euler characteristic) are unchanged. The sequential re-check is what stops 2-thick objects from
 * vanishing as under parallel deletion: the last voxel of a component is never simple, so no
 * component disappears.
 *   - Thinness: on return every object voxel is non-simple or a curve end. Closed surfaces around
 *     cavities stay surfaces (a curve cannot enclose a cavity); everything else becomes curves
 *     (a component with no tunnel and no end long enough may shrink to one voxel).
 *   - Determinism: the output does not depend on the number of threads (marking only reads).
 *   - Not guaranteed: a unique or exactly centred skeleton (order-dependent by a voxel or so);
 *     spurs longer than one voxel from bumps of the shape are kept, as by any end-point rule
 *     (unless the lifespan filter below is on).
 *
 * Lifespan filter (optional, ThinningOptions), the authors' rule for those spurs (Chaussard,
 * Noël, Biri & Couprie, DGCI 2013): the lifespan of a skeleton element is the number of passes
 * since it became 1D; it is kept iff lifespan > opening - distance (chessboard distance of the
 * voxel to the background and its opening, core/voxel/distance_transform.h).
 * Here: passes are numbered 1, 2, ... across both phases; a voxel is born at the end of the first
 * pass after which it has at most two object 26-neighbours (pass 0: already so in the input).
 * During pass P it is anchored, never deleted, iff born and P - birth > opening - distance; a
 * centre of its own maximal ball (opening == distance) is anchored from the pass after its
 * birth, a spur voxel near a bump (inside a larger ball) only after many passes. Curve-end status
 * no longer protects anything: unanchored simple voxels are candidates like any other, so spurs
 * erode from their tips (one or more voxels a pass) while the main branches wait to be anchored.
 * Born voxels also skip phase 1's opposite-neighbour condition (they are 1D, no layer is left to
 * keep): a tip whose only neighbour is diagonal has no face neighbour, so it could never be a
 * phase-1 candidate and would outlive its slack before phase 2 began.
 * Topology, the sequential re-check and thread-count independence are unchanged (births are
 * recorded in parallel from the current set only); on return every voxel is non-simple or
 * anchored. Extra cost: one neighbour count per unborn voxel and pass, 8 bytes per object voxel.
 * Grid border: voxels outside the grid are background (the object is padded by one empty layer).
 * Cost: O(passes * live object voxels); passes ~ half the largest object thickness.
 */
#include <cstdint>
#include <vector>

#include "core/voxel/grid_dims.h"

namespace gilab {

struct ThinningStats {
    uint32_t iterations = 0;  // passes of 6 subiterations, both phases, the last empty one counted
    uint64_t removed = 0;     // voxels deleted
    uint64_t anchored = 0;    // lifespan filter: voxels left that are anchored (0 without it)
};

/** The lifespan filter (file comment): both set, or both null for plain curve-end thinning. */
struct ThinningOptions {
    const std::vector<uint32_t>* distance = nullptr;  // chessboard distance of the object voxels
                                                      // to the background, grid-indexed
    const std::vector<uint32_t>* opening = nullptr;   // its opening (chessboardOpening)
};

/** Thins the object voxels (object[i] != 0) in place to a 26-connected curve skeleton (see the
 *  file comment for the algorithm and guarantees); remaining voxels are set to 1. Throws
 *  gilab::Error naming the problem when a dimension is 0, object.size() != nx*ny*nz, or the
 *  padded grid exceeds 2^32 voxels. */
ThinningStats thinCurveSkeleton(std::vector<uint8_t>& object, const GridDims& dims);

/** The same with options: with options.distance and options.opening set, the lifespan filter
 *  replaces curve-end protection (file comment); with both null, exactly the overload above.
 *  Also throws gilab::Error when only one is set or either's size != object.size(). */
ThinningStats thinCurveSkeleton(std::vector<uint8_t>& object, const GridDims& dims,
                                const ThinningOptions& options);

/** Exposed for tests: is voxel (x,y,z) a simple point of the object (26/6)? Looks only at its 26
 *  neighbours (the value of (x,y,z) itself is ignored); outside the grid is background. Throws
 *  gilab::Error on bad dims/size or (x,y,z) outside the grid. */
bool isSimplePoint(const std::vector<uint8_t>& object, const GridDims& dims, uint32_t x, uint32_t y,
                   uint32_t z);

/** Topological invariants of the object, for tests and checks: 26-components of the object,
 *  6-components of the background that do not touch the grid border (cavities), and the Euler
 *  characteristic of the union of closed voxel cubes (V - E + F - C). Tunnels = components +
 *  cavities - euler. */
struct Topology {
    uint32_t components = 0;
    uint32_t cavities = 0;
    int64_t euler = 0;
};

/** Computes Topology (serial, O(voxels)); throws gilab::Error on bad dims/size. */
Topology computeTopology(const std::vector<uint8_t>& object, const GridDims& dims);

}  // namespace gilab
