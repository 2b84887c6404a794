#include "cvgi_setup.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <numbers>
#include <string>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "core/util/error.h"
#include "core/vpl/vpl_math.h"

namespace gilab::cvgi {

namespace {

// ---------------------------------------------------------------------------------------------
// Shared helpers
// ---------------------------------------------------------------------------------------------

size_t linearIndex(const glm::ivec3& c, uint32_t n) {
    return size_t(c.x) + size_t(n) * (size_t(c.y) + size_t(n) * size_t(c.z));
}

/** Checks the CompactVoxels invariants the set-up relies on. */
void validateVoxels(const CompactVoxels& v, const char* who) {
    const size_t n = v.resolution;
    const std::string at = std::string("cvgi ") + who + ": CompactVoxels ";
    if (v.indexOf.size() != n * n * n)
        throw Error(at + "indexOf has " + std::to_string(v.indexOf.size()) +
                    " entries, expected N^3 = " + std::to_string(n * n * n));
    const size_t count = v.linear.size();
    if (v.albedo.size() != count)
        throw Error(at + "albedo has " + std::to_string(v.albedo.size()) +
                    " entries, expected V = " + std::to_string(count));
    const bool noFragments = count == 0 && v.fragmentOffset.empty();
    if (!noFragments &&
        (v.fragmentOffset.size() != count + 1 || v.fragmentOffset.back() > v.fragmentNormal.size()))
        throw Error(at + "fragmentOffset must have V + 1 entries ending <= fragmentNormal.size()");
}

glm::vec3 axisNormal(uint32_t face) {
    return glm::vec3(axisDirection(face));
}

/** Voxel centre in grid units (voxel i spans [i, i+1)). */
glm::dvec3 voxelCentre(const glm::ivec3& c) {
    return glm::dvec3(c) + 0.5;
}

// ---------------------------------------------------------------------------------------------
// Heuristic normal (§4.2, Fig. 7; notes 000 §2.2)
// ---------------------------------------------------------------------------------------------

/** Unoccupied voxels in the 3x3 slab adjacent on side `face`; outside the grid counts as free. */
int freeInSlab(const CompactVoxels& v, const glm::ivec3& c, uint32_t face) {
    const int a = int(face / 2), u = (a + 1) % 3, w = (a + 2) % 3;
    const glm::ivec3 base = c + axisDirection(face);
    int free = 0;
    for (int du = -1; du <= 1; ++du) {
        for (int dw = -1; dw <= 1; ++dw) {
            glm::ivec3 p = base;
            p[u] += du;
            p[w] += dw;
            if (v.at(p) == kEmpty) ++free;
        }
    }
    return free;
}

/** Tie-break of Fig. 7: sum over the voxel's fragments of angle(n_f, d), radians. */
double fragmentAngleSum(const CompactVoxels& v, uint32_t i, uint32_t face) {
    const glm::dvec3 d(axisDirection(face));
    double sum = 0.0;
    for (uint32_t f = v.fragmentOffset[i]; f < v.fragmentOffset[i + 1]; ++f)
        sum += std::acos(std::clamp(glm::dot(glm::dvec3(v.fragmentNormal[f]), d), -1.0, 1.0));
    return sum;
}

uint8_t heuristicNormal(const CompactVoxels& v, uint32_t i) {
    const glm::ivec3 c = v.coord(i);
    int free[6];
    int most = -1;
    for (uint32_t f = 0; f < 6; ++f) {
        free[f] = freeInSlab(v, c, f);
        most = std::max(most, free[f]);
    }
    // Most free slab wins; among ties, smallest fragment-angle sum; then first in face order.
    uint8_t best = 6;
    double bestSum = std::numeric_limits<double>::infinity();
    for (uint32_t f = 0; f < 6; ++f) {
        if (free[f] != most) continue;
        const double sum = fragmentAngleSum(v, i, f);
        if (best == 6 || sum < bestSum) {
            best = uint8_t(f);
            bestSum = sum;
        }
    }
    return best;
}

// ---------------------------------------------------------------------------------------------
// Clustering (Algorithm 1; notes 000 §2.3, §8.1, §8.2)
// ---------------------------------------------------------------------------------------------

/** Working state of one initial cluster during the iterations. */
struct WorkCluster {
    glm::vec3 centre;  // grid units
    glm::vec3 normal;  // unit
    bool live = true;  // false: the seed window holds no occupied voxel, never iterated
};

void validateClustering(const CompactVoxels& v, const std::vector<uint8_t>& axis,
                        const ClusteringParams& p) {
    validateVoxels(v, "clusterVoxels");
    if (p.initialClusters == 0) throw Error("cvgi clusterVoxels: initialClusters must be >= 1");
    if (p.iterations == 0) throw Error("cvgi clusterVoxels: iterations must be >= 1");
    if (!(p.angleDeg > 0.f && p.angleDeg <= 180.f))
        throw Error("cvgi clusterVoxels: angleDeg = " + std::to_string(p.angleDeg) +
                    " is outside (0, 180]");
    if (axis.size() != v.count())
        throw Error("cvgi clusterVoxels: axis has " + std::to_string(axis.size()) +
                    " entries, expected one per voxel (" + std::to_string(v.count()) + ")");
    for (uint8_t a : axis)
        if (a > 5) throw Error("cvgi clusterVoxels: axis entry " + std::to_string(a) + " > 5");
}

/** Seed spacing S = cbrt(N^3 / K), at least one voxel (notes 000 §2.3 [C]). */
double seedSpacing(uint32_t n, uint32_t k) {
    return std::max(1.0, double(n) / std::cbrt(double(k)));
}

/** Half width of the search window: ceil(S), SLIC's 2S region (notes 000 §8.2). */
int windowRadius(double s) {
    return int(std::ceil(s - 1e-6));
}

/** Voxel holding a centre, clamped to the grid: the window is centred on it. */
glm::ivec3 centreVoxel(const glm::vec3& centre, uint32_t n) {
    return glm::clamp(glm::ivec3(glm::floor(centre)), glm::ivec3(0), glm::ivec3(int(n) - 1));
}

/** Calls visit(compactIndex, coord) for each occupied voxel within Chebyshev r of c. */
template <class Visit>
void forEachOccupiedInWindow(const CompactVoxels& v, const glm::ivec3& c, int r, Visit&& visit) {
    const int n = int(v.resolution);
    const glm::ivec3 lo = glm::max(c - r, glm::ivec3(0));
    const glm::ivec3 hi = glm::min(c + r, glm::ivec3(n - 1));
    for (int z = lo.z; z <= hi.z; ++z) {
        for (int y = lo.y; y <= hi.y; ++y) {
            const uint32_t* row = &v.indexOf[linearIndex(glm::ivec3(0, y, z), v.resolution)];
            for (int x = lo.x; x <= hi.x; ++x)
                if (row[x] != kEmpty) visit(row[x], glm::ivec3(x, y, z));
        }
    }
}

/**
 * Seeds on the uniform grid ((i+0.5)S, (j+0.5)S, (k+0.5)S), i < ceil(N/S), each coordinate
 * clipped to the last voxel centre (SLIC's grid, §4.2). Initial normal: the axis normal of the
 * occupied voxel of the window nearest to the seed (ties: lowest compact index); the paper's
 * clusters start empty, SLIC moves seeds to a local best. No occupied voxel: dead seed.
 */
std::vector<WorkCluster> placeSeeds(const CompactVoxels& v, const std::vector<uint8_t>& axis,
                                    double s, int radius) {
    const uint32_t n = v.resolution;
    const int perAxis = n == 0 ? 0 : int(std::ceil(double(n) / s - 1e-9));
    std::vector<WorkCluster> seeds(size_t(perAxis) * perAxis * perAxis);
    const double last = double(n) - 0.5;
    tbb::parallel_for(size_t(0), seeds.size(), [&](size_t id) {
        const glm::ivec3 g(int(id % perAxis), int((id / perAxis) % perAxis),
                           int(id / (size_t(perAxis) * perAxis)));
        const glm::dvec3 p = glm::min((glm::dvec3(g) + 0.5) * s, glm::dvec3(last));
        WorkCluster& seed = seeds[id];
        seed.centre = glm::vec3(p);
        double nearest = std::numeric_limits<double>::infinity();
        uint32_t nearestVoxel = kEmpty;
        forEachOccupiedInWindow(v, centreVoxel(seed.centre, n), radius,
                                [&](uint32_t i, const glm::ivec3& c) {
                                    const glm::dvec3 d = voxelCentre(c) - p;
                                    const double d2 = glm::dot(d, d);
                                    if (d2 < nearest || (d2 == nearest && i < nearestVoxel)) {
                                        nearest = d2;
                                        nearestVoxel = i;
                                    }
                                });
        seed.live = nearestVoxel != kEmpty;
        seed.normal = seed.live ? axisNormal(axis[nearestVoxel]) : glm::vec3(0.f);
    });
    return seeds;
}

/**
 * Bit f set iff angle(cluster normal, axis f) < threshold: Eq. 1 gives distance 0 for those
 * (polarity corrected, notes 000 §8.1: the printed equation is inverted), 1 otherwise.
 */
uint8_t closeAxesMask(const glm::vec3& normal, double cosThreshold) {
    uint8_t mask = 0;
    for (uint32_t f = 0; f < 6; ++f)
        if (double(glm::dot(normal, axisNormal(f))) > cosThreshold) mask |= uint8_t(1u << f);
    return mask;
}

/**
 * Algorithm 1 lines 3-12 for one iteration. Each cluster claims a voxel of its window iff its
 * distance d is strictly lower than the stored one (line 7); the store starts at "max" (line 3),
 * so a voxel tested for the first time is always taken, even at d = 1 (§4.2). The GPU race is
 * resolved as if the clusters ran in index order (lower index wins ties): the final owner of a
 * voxel is the lowest-index cluster reaching the lowest d. An atomic minimum of (d << 32 | k)
 * computes exactly that in any order, so the clusters run in parallel and stay deterministic.
 */
void assignVoxels(const CompactVoxels& v, const std::vector<uint8_t>& axis,
                  const std::vector<WorkCluster>& clusters, int radius, double cosThreshold,
                  std::vector<uint64_t>& key) {
    std::fill(key.begin(), key.end(), std::numeric_limits<uint64_t>::max());  // line 3
    tbb::parallel_for(size_t(0), clusters.size(), [&](size_t k) {
        const WorkCluster& cl = clusters[k];
        if (!cl.live) return;
        const uint8_t close = closeAxesMask(cl.normal, cosThreshold);
        forEachOccupiedInWindow(  // lines 5-6
            v, centreVoxel(cl.centre, v.resolution), radius, [&](uint32_t i, const glm::ivec3&) {
                const uint64_t d = (close >> axis[i]) & 1u ? 0u : 1u;  // Eq. 1
                const uint64_t mine = (d << 32) | uint64_t(k);
                std::atomic_ref<uint64_t> stored(key[i]);
                uint64_t old = stored.load(std::memory_order_relaxed);
                while (mine < old &&
                       !stored.compare_exchange_weak(old, mine, std::memory_order_relaxed)) {
                }
            });
    });
}

uint32_t ownerOf(uint64_t key) {
    return key == std::numeric_limits<uint64_t>::max() ? kEmpty : uint32_t(key & 0xFFFFFFFFu);
}

/**
 * Algorithm 1 line 13: centre = mean of owned voxel centres, normal = normalised mean of owned
 * voxels' axis normals (the old one kept when that mean is zero). Returns the non-empty count.
 */
uint32_t updateClusters(const CompactVoxels& v, const std::vector<uint8_t>& axis,
                        const std::vector<uint64_t>& key, std::vector<WorkCluster>& clusters) {
    std::vector<uint32_t> count(clusters.size(), 0);
    std::vector<glm::dvec3> position(clusters.size(), glm::dvec3(0.0));
    std::vector<glm::dvec3> normal(clusters.size(), glm::dvec3(0.0));
    for (uint32_t i = 0; i < v.count(); ++i) {
        const uint32_t k = ownerOf(key[i]);
        if (k == kEmpty) continue;
        ++count[k];
        position[k] += voxelCentre(v.coord(i));
        normal[k] += glm::dvec3(axisDirection(axis[i]));
    }
    uint32_t nonEmpty = 0;
    for (size_t k = 0; k < clusters.size(); ++k) {
        if (count[k] == 0) continue;
        ++nonEmpty;
        clusters[k].centre = glm::vec3(position[k] / double(count[k]));
        const double len = glm::length(normal[k]);
        if (len > 0.0) clusters[k].normal = glm::vec3(normal[k] / len);
    }
    return nonEmpty;
}

/** Algorithm 1 line 16: drops empty clusters keeping index order; remaps the owners. */
std::vector<uint32_t> compactClusters(const std::vector<uint64_t>& key,
                                      const std::vector<WorkCluster>& work, Clusters& out) {
    std::vector<uint8_t> used(work.size(), 0);
    for (uint64_t k : key)
        if (ownerOf(k) != kEmpty) used[ownerOf(k)] = 1;
    std::vector<uint32_t> remap(work.size(), kEmpty);
    std::vector<uint32_t> survivors;
    for (size_t k = 0; k < work.size(); ++k) {
        if (!used[k]) continue;
        remap[k] = uint32_t(survivors.size());
        survivors.push_back(uint32_t(k));
    }
    out.owner.resize(key.size());
    out.unassigned = 0;
    for (size_t i = 0; i < key.size(); ++i) {
        const uint32_t k = ownerOf(key[i]);
        out.owner[i] = k == kEmpty ? kEmpty : remap[k];
        if (k == kEmpty) ++out.unassigned;
    }
    return survivors;
}

/** Voxel CSR: the voxels of each cluster in ascending compact index. */
void buildVoxelLists(Clusters& out, uint32_t clusterCount) {
    out.voxelOffset.assign(size_t(clusterCount) + 1, 0);
    for (uint32_t k : out.owner)
        if (k != kEmpty) ++out.voxelOffset[k + 1];
    for (uint32_t k = 0; k < clusterCount; ++k)
        out.voxelOffset[k + 1] += out.voxelOffset[k];
    out.voxels.resize(out.voxelOffset.back());
    std::vector<uint32_t> cursor(out.voxelOffset.begin(), out.voxelOffset.end() - 1);
    for (uint32_t i = 0; i < out.owner.size(); ++i)
        if (out.owner[i] != kEmpty) out.voxels[cursor[out.owner[i]]++] = i;
}

/** Clusters owning a 26-neighbour of any voxel of cluster k, sorted, without k. */
std::vector<uint32_t> neighbourClusters(const CompactVoxels& v, const Clusters& out, uint32_t k) {
    std::vector<uint32_t> found;
    for (uint32_t j = out.voxelOffset[k]; j < out.voxelOffset[k + 1]; ++j) {
        const glm::ivec3 c = v.coord(out.voxels[j]);
        for (int dz = -1; dz <= 1; ++dz)
            for (int dy = -1; dy <= 1; ++dy)
                for (int dx = -1; dx <= 1; ++dx) {
                    const uint32_t i = v.at(c + glm::ivec3(dx, dy, dz));
                    if (i == kEmpty) continue;
                    const uint32_t o = out.owner[i];
                    if (o != kEmpty && o != k) found.push_back(o);
                }
    }
    std::sort(found.begin(), found.end());
    found.erase(std::unique(found.begin(), found.end()), found.end());
    return found;
}

/**
 * Algorithm 1 lines 15 and 17: centre, normal, AABB, mean reflectance and neighbours of each
 * final cluster. `fallbackNormal` is the iteration normal, kept if the final mean is zero.
 */
void computeClusterInfo(const CompactVoxels& v, const std::vector<uint8_t>& axis,
                        const std::vector<glm::vec3>& fallbackNormal, Clusters& out) {
    const uint32_t count = uint32_t(fallbackNormal.size());
    out.centre.resize(count);
    out.normal.resize(count);
    out.aabbMin.resize(count);
    out.aabbMax.resize(count);
    out.reflectance.resize(count);
    std::vector<std::vector<uint32_t>> neighbours(count);
    tbb::parallel_for(uint32_t(0), count, [&](uint32_t k) {
        glm::dvec3 position(0.0), normal(0.0), albedo(0.0);
        glm::ivec3 lo(std::numeric_limits<int>::max()), hi(std::numeric_limits<int>::min());
        const uint32_t begin = out.voxelOffset[k], end = out.voxelOffset[k + 1];
        for (uint32_t j = begin; j < end; ++j) {
            const uint32_t i = out.voxels[j];
            const glm::ivec3 c = v.coord(i);
            position += voxelCentre(c);
            normal += glm::dvec3(axisDirection(axis[i]));
            albedo += glm::dvec3(v.albedo[i]);
            lo = glm::min(lo, c);
            hi = glm::max(hi, c);
        }
        const double n = double(end - begin);
        out.centre[k] = glm::vec3(position / n);
        const double len = glm::length(normal);
        out.normal[k] = len > 0.0 ? glm::vec3(normal / len) : fallbackNormal[k];
        out.reflectance[k] = glm::vec3(albedo / n);
        out.aabbMin[k] = lo;
        out.aabbMax[k] = hi;
        neighbours[k] = neighbourClusters(v, out, k);
    });
    out.neighbourOffset.assign(size_t(count) + 1, 0);
    for (uint32_t k = 0; k < count; ++k)
        out.neighbourOffset[k + 1] = out.neighbourOffset[k] + uint32_t(neighbours[k].size());
    out.neighbours.clear();
    out.neighbours.reserve(out.neighbourOffset.back());
    for (const auto& list : neighbours)
        out.neighbours.insert(out.neighbours.end(), list.begin(), list.end());
}

// ---------------------------------------------------------------------------------------------
// Visibility (§4.3; notes 000 §2.4, §7, §8.4, §8.5)
// ---------------------------------------------------------------------------------------------

/**
 * Integer 3D Bresenham from `from` to `to` (both included), dominant axis M known at compile time
 * (so the coordinates stay in registers): one unit step per iteration along M, the two other axes
 * U, W stepped when their error term turns positive. visit(p) returns false to stop.
 */
template <int M, class Visit>
void walkAlong(glm::ivec3 p, const glm::ivec3& a, const glm::ivec3& step, Visit& visit) {
    constexpr int U = (M + 1) % 3, W = (M + 2) % 3;
    int errU = 2 * a[U] - a[M], errW = 2 * a[W] - a[M];
    for (int i = 0;; ++i) {
        if (!visit(p) || i == a[M]) return;
        p[M] += step[M];
        if (errU > 0) {
            p[U] += step[U];
            errU -= 2 * a[M];
        }
        if (errW > 0) {
            p[W] += step[W];
            errW -= 2 * a[M];
        }
        errU += 2 * a[U];
        errW += 2 * a[W];
    }
}

template <class Visit>
void walkBresenham(glm::ivec3 from, glm::ivec3 to, Visit&& visit) {
    const glm::ivec3 a = glm::abs(to - from);
    const glm::ivec3 step = glm::sign(to - from);
    if (a.x >= a.y && a.x >= a.z)
        walkAlong<0>(from, a, step, visit);
    else if (a.y >= a.z)
        walkAlong<1>(from, a, step, visit);
    else
        walkAlong<2>(from, a, step, visit);
}

double radicalInverse2(uint32_t i) {
    i = (i << 16) | (i >> 16);
    i = ((i & 0x55555555u) << 1) | ((i & 0xAAAAAAAAu) >> 1);
    i = ((i & 0x33333333u) << 2) | ((i & 0xCCCCCCCCu) >> 2);
    i = ((i & 0x0F0F0F0Fu) << 4) | ((i & 0xF0F0F0F0u) >> 4);
    i = ((i & 0x00FF00FFu) << 8) | ((i & 0xFF00FF00u) >> 8);
    return double(i) * 0x1p-32;
}

/** Per face, the integer end offset round(dir * 2N) of each ray (notes 000 §8.4). */
std::vector<glm::ivec3> rayDeltas(uint32_t rays, uint32_t n, double rotation) {
    const std::vector<glm::vec3> local = hemisphereDirections(rays, rotation);
    std::vector<glm::ivec3> deltas(6 * size_t(rays));
    for (uint32_t f = 0; f < 6; ++f)
        for (uint32_t r = 0; r < rays; ++r)
            deltas[f * size_t(rays) + r] =
                glm::ivec3(glm::round(toFaceFrame(local[r], f) * (2.f * float(n))));
    return deltas;
}

/**
 * The paper's atomic de-duplication, one task per face: stamp[k] == face id marks cluster k as
 * already listed for the current face (`stamp` has one entry per cluster id).
 */
struct FaceDedup {
    std::vector<uint32_t> stamp;
    std::vector<uint32_t> slot;  // the cluster's entry in the face's list (valid when stamped)
    uint32_t face = 0;

    explicit FaceDedup(uint32_t clusterIds) : stamp(clusterIds, 0), slot(clusterIds, 0) {}
    void nextFace() { ++face; }
    bool firstTime(uint32_t cluster) {
        if (stamp[cluster] == face) return false;
        stamp[cluster] = face;
        return true;
    }
};

/** A face's entries as traceFace fills them: ids, ray counts and facing cosine sums. */
struct FaceEntries {
    std::vector<uint32_t>& clusters;
    std::vector<uint32_t>& hits;
    std::vector<float>& cosineSums;
};

/**
 * Appends the distinct clusters seen from face f of voxel i to `out`, in first-hit ray order,
 * with each cluster's ray count and the cosines (to the face's axis) of its rays that met the
 * cluster's front (`cosines[r]`, `directions[r]` of ray r in world axes). Rays start at c + axis
 * (the voxel in front of the face) and stop at the first occupied voxel, the start included (a
 * buried face sees only its neighbour's cluster), or on leaving the grid. An unassigned voxel
 * blocks and adds nothing. Returns whether the face is buried.
 */
bool traceFace(const CompactVoxels& v, const Clusters& cl, const glm::ivec3* deltas,
               const glm::vec3* directions, const float* cosines, uint32_t rays, uint32_t i,
               uint32_t f, FaceDedup& dedup, FaceEntries& out) {
    dedup.nextFace();
    const size_t first = out.clusters.size();
    auto add = [&](uint32_t owner, uint32_t r) {
        if (dedup.firstTime(owner)) {
            dedup.slot[owner] = uint32_t(out.clusters.size() - first);
            out.clusters.push_back(owner);
            out.hits.push_back(0);
            out.cosineSums.push_back(0.0f);
        }
        const size_t e = first + dedup.slot[owner];
        ++out.hits[e];
        const bool front =
            owner >= cl.normal.size() || glm::dot(cl.normal[owner], directions[r]) < 0.0f;
        if (front) out.cosineSums[e] += cosines[r];
    };
    const glm::ivec3 start = v.coord(i) + axisDirection(f);
    if (!v.inside(start)) return false;
    if (const uint32_t hit = v.at(start); hit != kEmpty) {  // buried: every ray stops here
        if (cl.owner[hit] != kEmpty)
            for (uint32_t r = 0; r < rays; ++r)
                add(cl.owner[hit], r);
        return true;
    }
    const size_t n = v.resolution;
    for (uint32_t r = 0; r < rays; ++r) {
        walkBresenham(start, start + deltas[r], [&](const glm::ivec3& p) {
            if (uint32_t(p.x) >= n || uint32_t(p.y) >= n || uint32_t(p.z) >= n) return false;
            const uint32_t hit = v.indexOf[size_t(p.x) + n * (size_t(p.y) + n * size_t(p.z))];
            if (hit == kEmpty) return true;
            const uint32_t owner = cl.owner[hit];
            if (owner != kEmpty) add(owner, r);
            return false;
        });
    }
    return false;
}

/** One more than the largest owner id (the Clusters may carry only `owner`). */
uint32_t clusterIdRange(const Clusters& cl) {
    uint32_t range = cl.count();
    for (uint32_t o : cl.owner)
        if (o != kEmpty) range = std::max(range, o + 1);
    return range;
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// Public API
// ---------------------------------------------------------------------------------------------

std::vector<uint8_t> heuristicNormals(const CompactVoxels& voxels) {
    validateVoxels(voxels, "heuristicNormals");
    std::vector<uint8_t> axis(voxels.count());
    tbb::parallel_for(uint32_t(0), voxels.count(),
                      [&](uint32_t i) { axis[i] = heuristicNormal(voxels, i); });
    return axis;
}

Clusters clusterVoxels(const CompactVoxels& voxels, const std::vector<uint8_t>& axis,
                       const ClusteringParams& params) {
    validateClustering(voxels, axis, params);
    Clusters out;
    const double s = seedSpacing(voxels.resolution, params.initialClusters);
    const int radius = windowRadius(s);
    out.seedSpacing = float(s);
    std::vector<WorkCluster> work = placeSeeds(voxels, axis, s, radius);
    out.seeds = uint32_t(work.size());
    out.deadSeeds = uint32_t(
        std::count_if(work.begin(), work.end(), [](const WorkCluster& w) { return !w.live; }));

    // angle < threshold  <=>  cos(angle) > cos(threshold), both in [0, 180] degrees.
    const double cosThreshold = std::cos(double(params.angleDeg) * std::numbers::pi / 180.0);
    std::vector<uint64_t> key(voxels.count());
    for (uint32_t it = 0; it < params.iterations; ++it) {  // line 2
        assignVoxels(voxels, axis, work, radius, cosThreshold, key);
        out.nonEmptyPerIteration.push_back(updateClusters(voxels, axis, key, work));
    }

    const std::vector<uint32_t> survivors = compactClusters(key, work, out);
    std::vector<glm::vec3> fallbackNormal(survivors.size());
    for (size_t k = 0; k < survivors.size(); ++k)
        fallbackNormal[k] = work[survivors[k]].normal;
    buildVoxelLists(out, uint32_t(survivors.size()));
    computeClusterInfo(voxels, axis, fallbackNormal, out);
    return out;
}

uint32_t paperInitialClusters(uint32_t resolution) {
    if (resolution == 0) throw Error("cvgi paperInitialClusters: resolution must be >= 1");
    struct Entry {
        uint32_t n, k;
    };
    static constexpr Entry kTable[] = {
        {32, 25000}, {64, 30000}, {128, 250000}, {256, 120000}, {512, 250000}};
    const double logN = std::log2(double(resolution));
    const Entry* best = &kTable[0];
    for (const Entry& e : kTable)
        if (std::abs(std::log2(double(e.n)) - logN) < std::abs(std::log2(double(best->n)) - logN))
            best = &e;
    if (best->n == resolution) return best->k;
    // Same seed spacing as the nearest listed resolution.
    const double scale = double(resolution) / double(best->n);
    return uint32_t(std::max(1.0, std::round(double(best->k) * scale * scale * scale)));
}

ClusterSightings clusterSightings(const FaceVisibility& visibility, uint32_t clusterIds) {
    ClusterSightings out;
    out.rayHits.assign(clusterIds, 0);
    out.faceHits.assign(clusterIds, 0);
    out.rays = visibility.rays;
    const size_t faces = visibility.buried.size();
    for (size_t f = 0; f < faces; ++f) {
        if (visibility.buried[f]) continue;
        ++out.openFaces;
        for (uint32_t e = visibility.offset[f]; e < visibility.offset[f + 1]; ++e) {
            const uint32_t c = visibility.clusters[e];
            if (c >= clusterIds) continue;
            out.rayHits[c] += visibility.hits[e];
            ++out.faceHits[c];
            ++out.openEntries;
        }
    }
    return out;
}

std::vector<glm::vec3> hemisphereDirections(uint32_t rays, double rotation) {
    std::vector<glm::vec3> dirs(rays);
    for (uint32_t i = 0; i < rays; ++i) {
        // Uniform in solid angle, one ray at the centre of each of `rays` equal cos-theta
        // strata: the cosines sum to exactly rays / 2, so ray_weighted's (2 pi / rays) sum of
        // L cos is exact under uniform radiance (1 - i / rays summed to (rays + 1) / 2, which
        // biased it by (rays + 1) / rays: +3.1 % at 32 rays).
        const double cosTheta = 1.0 - (double(i) + 0.5) / double(rays);
        const double sinTheta = std::sqrt(std::max(0.0, 1.0 - cosTheta * cosTheta));
        // The seed's rotation about +z: a Cranley-Patterson shift of the azimuth alone (x + 0
        // is x, so rotation 0 is the unrotated set bit for bit).
        double azimuth = radicalInverse2(i) + rotation;
        if (azimuth >= 1.0) azimuth -= 1.0;
        const double phi = 2.0 * std::numbers::pi * azimuth;
        dirs[i] =
            glm::vec3(glm::dvec3(sinTheta * std::cos(phi), sinTheta * std::sin(phi), cosTheta));
    }
    return dirs;
}

double seedRotation(uint32_t seed) {
    return double(vpl::cranleyPattersonShift(seed).x);
}

glm::vec3 toFaceFrame(const glm::vec3& local, uint32_t face) {
    const int a = int(face / 2), u = (a + 1) % 3, w = (a + 2) % 3;
    glm::vec3 out;
    out[a] = (face & 1u) ? local.z : -local.z;
    out[u] = local.x;
    out[w] = local.y;
    return out;
}

std::vector<glm::ivec3> bresenhamLine(glm::ivec3 from, glm::ivec3 to) {
    std::vector<glm::ivec3> line;
    walkBresenham(from, to, [&](const glm::ivec3& p) {
        line.push_back(p);
        return true;
    });
    return line;
}

FaceVisibility faceVisibility(const CompactVoxels& voxels, const Clusters& clusters,
                              const VisibilityParams& params) {
    validateVoxels(voxels, "faceVisibility");
    if (params.raysPerFace == 0) throw Error("cvgi faceVisibility: raysPerFace must be >= 1");
    if (clusters.owner.size() != voxels.count())
        throw Error("cvgi faceVisibility: clusters.owner has " +
                    std::to_string(clusters.owner.size()) + " entries, expected " +
                    std::to_string(voxels.count()));
    const uint32_t rays = params.raysPerFace, count = voxels.count();
    if (!(params.rotation >= 0.0 && params.rotation < 1.0))
        throw Error("cvgi faceVisibility: rotation must be in [0, 1) turns");
    const std::vector<glm::ivec3> deltas = rayDeltas(rays, voxels.resolution, params.rotation);
    const std::vector<glm::vec3> local = hemisphereDirections(rays, params.rotation);
    std::vector<glm::vec3> directions(6 * size_t(rays));
    std::vector<float> cosines(rays);
    for (uint32_t r = 0; r < rays; ++r) {
        cosines[r] = local[r].z;
        for (uint32_t f = 0; f < 6; ++f)
            directions[f * size_t(rays) + r] = toFaceFrame(local[r], f);
    }
    const uint32_t idRange = clusterIdRange(clusters);

    // Fixed chunks of voxels, each filled by one task and concatenated in order: the result does
    // not depend on the thread count.
    constexpr uint32_t kChunk = 64;
    const uint32_t chunks = (count + kChunk - 1) / kChunk;
    struct Chunk {
        std::vector<uint32_t> counts, clusters, hits;
        std::vector<float> cosineSums;
        std::vector<uint8_t> buried;
    };
    std::vector<Chunk> chunk(chunks);
    tbb::parallel_for(uint32_t(0), chunks, [&](uint32_t c) {
        const uint32_t begin = c * kChunk, end = std::min(count, begin + kChunk);
        Chunk& k = chunk[c];
        FaceEntries entries{k.clusters, k.hits, k.cosineSums};
        FaceDedup dedup(idRange);
        k.counts.reserve(6 * size_t(end - begin));
        for (uint32_t i = begin; i < end; ++i) {
            for (uint32_t f = 0; f < 6; ++f) {
                const size_t before = k.clusters.size();
                const bool buried = traceFace(voxels, clusters, &deltas[f * size_t(rays)],
                                              &directions[f * size_t(rays)], cosines.data(), rays,
                                              i, f, dedup, entries);
                k.counts.push_back(uint32_t(k.clusters.size() - before));
                k.buried.push_back(buried ? 1 : 0);
            }
        }
    });

    FaceVisibility out;
    out.rays = rays;
    out.offset.reserve(6 * size_t(count) + 1);
    out.offset.push_back(0);
    for (uint32_t c = 0; c < chunks; ++c) {
        for (uint32_t n : chunk[c].counts) {
            out.offset.push_back(out.offset.back() + n);
            out.maxPerFace = std::max(out.maxPerFace, n);
        }
        out.clusters.insert(out.clusters.end(), chunk[c].clusters.begin(), chunk[c].clusters.end());
        out.hits.insert(out.hits.end(), chunk[c].hits.begin(), chunk[c].hits.end());
        out.cosineSums.insert(out.cosineSums.end(), chunk[c].cosineSums.begin(),
                              chunk[c].cosineSums.end());
        out.buried.insert(out.buried.end(), chunk[c].buried.begin(), chunk[c].buried.end());
    }
    out.raysTraced = uint64_t(count) * 6 * rays;
    out.uncompactedEntries = uint64_t(count) * 6 * rays;
    out.paperEntries = uint64_t(count) * uint64_t(voxels.resolution) * 6;
    return out;
}

}  // namespace gilab::cvgi
