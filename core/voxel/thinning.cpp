#include "core/voxel/thinning.h"

#include <algorithm>
#include <array>
#include <bit>
#include <limits>
#include <string>
#include <utility>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "core/util/error.h"

namespace gilab {
namespace {

// ---------------------------------------------------------------------------------------------
// 3x3x3 neighbourhood as a 27-bit mask: bit (dx+1) + 3(dy+1) + 9(dz+1), centre = bit 13
// ---------------------------------------------------------------------------------------------

constexpr int kCentre = 13;

struct NeighbourTables {
    std::array<uint32_t, 27> adj26{};  // 26-neighbours of each cell inside the 3x3x3 cube
    std::array<uint32_t, 27> adj6{};   // 6-neighbours of each cell inside the 3x3x3 cube
    uint32_t n26 = 0;                  // N26*(p): all but the centre
    uint32_t n18 = 0;                  // N18*(p): no corners, no centre
    uint32_t n6 = 0;                   // N6*(p)
};

constexpr NeighbourTables makeTables() {
    NeighbourTables t;
    for (int a = 0; a < 27; ++a) {
        const int ax = a % 3, ay = a / 3 % 3, az = a / 9;
        const int da = (ax != 1) + (ay != 1) + (az != 1);  // 1 face, 2 edge, 3 corner
        if (da >= 1) t.n26 |= 1u << a;
        if (da >= 1 && da <= 2) t.n18 |= 1u << a;
        if (da == 1) t.n6 |= 1u << a;
        for (int b = 0; b < 27; ++b) {
            const int bx = b % 3, by = b / 3 % 3, bz = b / 9;
            const int dx = ax > bx ? ax - bx : bx - ax, dy = ay > by ? ay - by : by - ay;
            const int dz = az > bz ? az - bz : bz - az;
            if (a == b || dx > 1 || dy > 1 || dz > 1) continue;
            t.adj26[a] |= 1u << b;
            if (dx + dy + dz == 1) t.adj6[a] |= 1u << b;
        }
    }
    return t;
}

constexpr NeighbourTables kTables = makeTables();

/** Number of components of `set` (under `adj`) that meet `seeds`; stops counting at 2. */
int countComponents(uint32_t set, const std::array<uint32_t, 27>& adj, uint32_t seeds) {
    int count = 0;
    while ((set & seeds) != 0 && count < 2) {
        uint32_t component = (set & seeds) & (~(set & seeds) + 1);  // lowest seed bit
        uint32_t frontier = component;
        while (frontier != 0) {
            uint32_t grow = 0;
            for (uint32_t f = frontier; f != 0; f &= f - 1)
                grow |= adj[std::countr_zero(f)];
            frontier = grow & set & ~component;
            component |= frontier;
        }
        set &= ~component;
        ++count;
    }
    return count;
}

/** Bertrand & Malandain 1994 (26/6): simple iff T26(p, X) = 1 and T6(p, ~X) = 1, where
 *  T6 counts the 6-components of ~X in N18*(p) that are 6-adjacent to p. */
bool isSimpleMask(uint32_t mask) {
    const uint32_t object = mask & kTables.n26;
    if (object == 0 || countComponents(object, kTables.adj26, kTables.n26) != 1) return false;
    const uint32_t background = ~mask & kTables.n18;
    return countComponents(background, kTables.adj6, kTables.n6) == 1;
}

void validate(size_t size, const GridDims& d, const char* who) {
    if (d.nx == 0 || d.ny == 0 || d.nz == 0) {
        throw Error(std::string(who) + ": grid dimension is 0 (" + std::to_string(d.nx) + "x" +
                    std::to_string(d.ny) + "x" + std::to_string(d.nz) + ")");
    }
    const uint64_t padded = uint64_t(d.nx + 2ull) * (d.ny + 2ull) * (d.nz + 2ull);
    if (padded > std::numeric_limits<uint32_t>::max()) {
        throw Error(std::string(who) + ": grid too large for 32-bit voxel indices");
    }
    const uint64_t expected = uint64_t(d.nx) * d.ny * d.nz;
    if (size != expected) {
        throw Error(std::string(who) + ": object has " + std::to_string(size) + " voxels, dims " +
                    std::to_string(d.nx) + "x" + std::to_string(d.ny) + "x" + std::to_string(d.nz) +
                    " need " + std::to_string(expected));
    }
}

// ---------------------------------------------------------------------------------------------
// Grid padded by one background layer, so every voxel has all 26 neighbours in memory
// ---------------------------------------------------------------------------------------------

struct PaddedGrid {
    uint32_t px, py, pz;
    std::vector<uint8_t> v;
    std::array<int64_t, 27> offset{};  // index offset of each mask bit

    PaddedGrid(const std::vector<uint8_t>& object, const GridDims& d)
        : px(d.nx + 2), py(d.ny + 2), pz(d.nz + 2), v(size_t(px) * py * pz, 0) {
        for (int b = 0; b < 27; ++b) {
            offset[b] = (b % 3 - 1) + int64_t(px) * ((b / 3 % 3 - 1) + int64_t(py) * (b / 9 - 1));
        }
        for (uint32_t z = 0; z < d.nz; ++z) {
            for (uint32_t y = 0; y < d.ny; ++y) {
                const size_t src = size_t(d.nx) * (y + size_t(d.ny) * z);
                const size_t dst = index(1, y + 1, z + 1);
                for (uint32_t x = 0; x < d.nx; ++x)
                    v[dst + x] = object[src + x] != 0;
            }
        }
    }
    size_t index(uint32_t x, uint32_t y, uint32_t z) const {
        return x + size_t(px) * (y + size_t(py) * z);
    }
    uint32_t mask(size_t i) const {
        uint32_t m = 0;
        for (int b = 0; b < 27; ++b)
            m |= uint32_t(v[i + offset[b]]) << b;
        return m;
    }
    void copyBack(std::vector<uint8_t>& object, const GridDims& d) const {
        for (uint32_t z = 0; z < d.nz; ++z) {
            for (uint32_t y = 0; y < d.ny; ++y) {
                const size_t dst = size_t(d.nx) * (y + size_t(d.ny) * z);
                const size_t src = index(1, y + 1, z + 1);
                for (uint32_t x = 0; x < d.nx; ++x)
                    object[dst + x] = v[src + x];
            }
        }
    }
};

// Mask bits of the 6 directions in subiteration order U, D, N, S, E, W (+z, -z, +y, -y, +x, -x).
constexpr int kDirectionBit[6] = {22, 4, 16, 10, 14, 12};
constexpr int kOppositeBit[6] = {4, 22, 10, 16, 12, 14};

/** Curve end: exactly one object 26-neighbour q, and q has exactly two. A tip whose neighbour is
 *  a junction or part of a sheet is not a curve end, so 1-voxel spurs are not kept. */
bool isCurveEnd(const PaddedGrid& g, size_t i, uint32_t mask) {
    const uint32_t object = mask & kTables.n26;
    if (std::popcount(object) != 1) return false;
    const size_t q = i + g.offset[std::countr_zero(object)];
    return std::popcount(g.mask(q) & kTables.n26) == 2;
}

// ---------------------------------------------------------------------------------------------
// Lifespan filter (Chaussard, Noel, Biri & Couprie 2013)
// ---------------------------------------------------------------------------------------------

constexpr uint32_t kUnborn = std::numeric_limits<uint32_t>::max();

/** Per live voxel (parallel to `live`): the pass at whose end it first had at most two object
 *  26-neighbours (kUnborn before), and opening - distance, the lifespan it must exceed. */
struct Lifespan {
    std::vector<uint32_t> birth;
    std::vector<int32_t> slack;  // clamped to int32: lifespans are pass counts, far below 2^31

    /** Anchored (never deleted) during pass `pass`: born, and pass - birth > slack. */
    bool anchored(size_t k, uint32_t pass) const {
        return birth[k] != kUnborn && int64_t(pass) - int64_t(birth[k]) > slack[k];
    }
};

/** One subiteration of direction `dir`: parallel marking on the current set, then sequential
 *  deletion in ascending index order re-checking simplicity (Lee, Kashyap & Chu 1994). Phase 1
 *  (`phase1`) also asks the opposite neighbour to be object and takes curve-end status from the
 *  marking; phase 2 re-checks it at deletion. With `lifespan`, anchoring (fixed for the pass
 *  `pass`) replaces the curve-end test in both. Returns the number deleted. */
uint64_t runSubiteration(PaddedGrid& g, const std::vector<uint32_t>& live, int dir, bool phase1,
                         std::vector<uint8_t>& marked, const Lifespan* lifespan, uint32_t pass) {
    const int64_t dOff = g.offset[kDirectionBit[dir]];
    const int64_t oppOff = g.offset[kOppositeBit[dir]];
    marked.assign(live.size(), 0);
    // Mark simple d-border points that are not curve ends, or with `lifespan` not anchored
    // (reads only: thread-count independent)
    tbb::parallel_for(
        tbb::blocked_range<size_t>(0, live.size(), 2048), [&](const tbb::blocked_range<size_t>& r) {
            for (size_t k = r.begin(); k != r.end(); ++k) {
                const size_t i = live[k];
                if (g.v[i] == 0 || g.v[i + dOff] != 0) continue;
                if (lifespan != nullptr) {
                    // Phase 1's opposite-neighbour rule keeps layers; a born voxel is 1D already
                    if (phase1 && g.v[i + oppOff] == 0 && lifespan->birth[k] == kUnborn) continue;
                    marked[k] = !lifespan->anchored(k, pass) && isSimpleMask(g.mask(i));
                    continue;
                }
                if (phase1 && g.v[i + oppOff] == 0) continue;
                const uint32_t mask = g.mask(i);
                marked[k] = isSimpleMask(mask) && !isCurveEnd(g, i, mask);
            }
        });
    // Delete sequentially; each deletion is of a point simple in the current set
    uint64_t removed = 0;
    for (size_t k = 0; k < live.size(); ++k) {
        if (marked[k] == 0) continue;
        const size_t i = live[k];
        const uint32_t mask = g.mask(i);
        if (isSimpleMask(mask) && (phase1 || lifespan != nullptr || !isCurveEnd(g, i, mask))) {
            g.v[i] = 0;
            ++removed;
        }
    }
    return removed;
}

}  // namespace

ThinningStats thinCurveSkeleton(std::vector<uint8_t>& object, const GridDims& dims) {
    return thinCurveSkeleton(object, dims, ThinningOptions{});
}

ThinningStats thinCurveSkeleton(std::vector<uint8_t>& object, const GridDims& dims,
                                const ThinningOptions& options) {
    validate(object.size(), dims, "thinCurveSkeleton");
    const bool useLifespan = options.distance != nullptr || options.opening != nullptr;
    if (useLifespan) {
        if (options.distance == nullptr || options.opening == nullptr) {
            throw Error(std::string("thinCurveSkeleton: the lifespan filter needs both ") +
                        "ThinningOptions::distance and ::opening, got only " +
                        (options.distance != nullptr ? "distance" : "opening"));
        }
        for (const auto& [map, name] :
             {std::pair{options.distance, "distance"}, std::pair{options.opening, "opening"}}) {
            if (map->size() != object.size()) {
                throw Error(std::string("thinCurveSkeleton: ThinningOptions::") + name + " has " +
                            std::to_string(map->size()) + " values, the object " +
                            std::to_string(object.size()));
            }
        }
    }
    PaddedGrid g(object, dims);
    std::vector<uint32_t> live;  // padded indices of object voxels, ascending
    for (size_t i = 0; i < g.v.size(); ++i) {
        if (g.v[i] != 0) live.push_back(uint32_t(i));
    }
    ThinningStats stats;
    Lifespan lifespan;
    // Records as born at pass `pass` every unborn live voxel with at most two object neighbours
    const auto recordBirths = [&](uint32_t pass) {
        tbb::parallel_for(tbb::blocked_range<size_t>(0, live.size(), 2048),
                          [&](const tbb::blocked_range<size_t>& r) {
                              for (size_t k = r.begin(); k != r.end(); ++k) {
                                  if (lifespan.birth[k] != kUnborn) continue;
                                  if (std::popcount(g.mask(live[k]) & kTables.n26) <= 2) {
                                      lifespan.birth[k] = pass;
                                  }
                              }
                          });
    };
    if (useLifespan) {
        lifespan.birth.assign(live.size(), kUnborn);
        lifespan.slack.resize(live.size());
        for (size_t k = 0; k < live.size(); ++k) {
            // Padded index to grid index: x + 1 + px * (y + 1 + py * (z + 1))
            const uint32_t i = live[k];
            const uint32_t x = i % g.px - 1, y = i / g.px % g.py - 1, z = i / g.px / g.py - 1;
            const size_t j = dims.index(x, y, z);
            const int64_t slack = int64_t((*options.opening)[j]) - int64_t((*options.distance)[j]);
            lifespan.slack[k] = int32_t(std::clamp<int64_t>(
                slack, std::numeric_limits<int32_t>::min(), std::numeric_limits<int32_t>::max()));
        }
        recordBirths(0);  // already a curve in the input: born before the first pass
    }
    std::vector<uint8_t> marked;
    for (const bool phase1 : {true, false}) {
        // Passes of U, D, N, S, E, W until one deletes nothing
        for (;;) {
            uint64_t removed = 0;
            const uint32_t pass = stats.iterations + 1;
            for (int dir = 0; dir < 6; ++dir) {
                removed += runSubiteration(g, live, dir, phase1, marked,
                                           useLifespan ? &lifespan : nullptr, pass);
            }
            ++stats.iterations;
            stats.removed += removed;
            if (removed == 0) break;
            if (!useLifespan) {
                std::erase_if(live, [&](uint32_t i) { return g.v[i] == 0; });
                continue;
            }
            size_t kept = 0;  // compact live and its lifespan records together
            for (size_t k = 0; k < live.size(); ++k) {
                if (g.v[live[k]] == 0) continue;
                live[kept] = live[k];
                lifespan.birth[kept] = lifespan.birth[k];
                lifespan.slack[kept] = lifespan.slack[k];
                ++kept;
            }
            live.resize(kept);
            lifespan.birth.resize(kept);
            lifespan.slack.resize(kept);
            recordBirths(pass);
        }
    }
    if (useLifespan) {
        // The anchoring in force during the last pass, which deleted nothing
        for (size_t k = 0; k < live.size(); ++k)
            stats.anchored += lifespan.anchored(k, stats.iterations);
    }
    g.copyBack(object, dims);
    return stats;
}

bool isSimplePoint(const std::vector<uint8_t>& object, const GridDims& dims, uint32_t x, uint32_t y,
                   uint32_t z) {
    validate(object.size(), dims, "isSimplePoint");
    if (x >= dims.nx || y >= dims.ny || z >= dims.nz) {
        throw Error("isSimplePoint: voxel (" + std::to_string(x) + "," + std::to_string(y) + "," +
                    std::to_string(z) + ") is outside the grid");
    }
    uint32_t mask = 0;
    for (int b = 0; b < 27; ++b) {
        const int64_t qx = int64_t(x) + b % 3 - 1, qy = int64_t(y) + b / 3 % 3 - 1;
        const int64_t qz = int64_t(z) + b / 9 - 1;
        if (b == kCentre || qx < 0 || qy < 0 || qz < 0 || qx >= dims.nx || qy >= dims.ny ||
            qz >= dims.nz) {
            continue;
        }
        mask |= uint32_t(object[qx + dims.nx * (qy + size_t(dims.ny) * qz)] != 0) << b;
    }
    return isSimpleMask(mask);
}

Topology computeTopology(const std::vector<uint8_t>& object, const GridDims& dims) {
    validate(object.size(), dims, "computeTopology");
    const PaddedGrid g(object, dims);
    Topology topo;
    std::vector<uint8_t> seen(g.v.size(), 0);
    std::vector<size_t> stack;
    // Flood-fill the set {value == v[start]} from start under 26- (object) or 6-adjacency
    const auto fill = [&](size_t start, bool adj26) {
        const uint8_t value = g.v[start];
        seen[start] = 1;
        stack.assign(1, start);
        while (!stack.empty()) {
            const size_t i = stack.back();
            stack.pop_back();
            const uint32_t bits = adj26 ? kTables.n26 : kTables.n6;
            for (uint32_t b = bits; b != 0; b &= b - 1) {
                const int64_t q = int64_t(i) + g.offset[std::countr_zero(b)];
                if (q < 0 || size_t(q) >= g.v.size() || seen[q] || g.v[q] != value) continue;
                // The padding frame wraps in x/y at row ends; it is all background and connected
                // anyway, and object voxels never touch it, so wrapped steps change nothing.
                seen[q] = 1;
                stack.push_back(size_t(q));
            }
        }
    };
    fill(0, false);  // the outside: background touching the grid border, through the padding
    for (size_t i = 0; i < g.v.size(); ++i) {
        if (seen[i]) continue;
        fill(i, g.v[i] != 0);
        if (g.v[i] != 0) {
            ++topo.components;
        } else {
            ++topo.cavities;
        }
    }
    // Euler characteristic of the union of closed unit cubes: V - E + F - C, each cell counted
    // once if it bounds an object voxel. Cell (i,j,k) has its lower corner at voxel (i,j,k).
    const auto at = [&](uint32_t x, uint32_t y, uint32_t z) { return g.v[g.index(x, y, z)]; };
    int64_t vertices = 0, edges = 0, faces = 0, cubes = 0;
    for (uint32_t z = 1; z < g.pz; ++z) {
        for (uint32_t y = 1; y < g.py; ++y) {
            for (uint32_t x = 1; x < g.px; ++x) {
                const bool c000 = at(x, y, z), c100 = at(x - 1, y, z), c010 = at(x, y - 1, z);
                const bool c001 = at(x, y, z - 1), c110 = at(x - 1, y - 1, z);
                const bool c101 = at(x - 1, y, z - 1), c011 = at(x, y - 1, z - 1);
                const bool c111 = at(x - 1, y - 1, z - 1);
                cubes += c000;
                faces += (c000 || c100) + (c000 || c010) + (c000 || c001);
                edges += (c000 || c010 || c001 || c011) + (c000 || c100 || c001 || c101) +
                         (c000 || c100 || c010 || c110);
                vertices += c000 || c100 || c010 || c001 || c110 || c101 || c011 || c111;
            }
        }
    }
    topo.euler = vertices - edges + faces - cubes;
    return topo;
}

}  // namespace gilab
