#include "reference/spawn.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>
#include <utility>

#include <tbb/parallel_for.h>

namespace gilab::ref {
namespace {

constexpr double kEps = 0x1p-24;    // float's unit roundoff
constexpr double kSafety = 8.0;     // margin = 8 x the error estimate
constexpr double kShapeCap = 64.0;  // slivers: beyond this their normal is noise (see the doc)
constexpr int kMaxPlanes = 32;
constexpr int kProjectRounds = 8;
constexpr int kNudgeRounds = 16;

/** One constraint: dot(n, o) - d >= margin (n unit, pointing to the path's side). */
struct Plane {
    glm::dvec3 n;
    double d;
    double margin;
};

/** The next float after x towards +inf (up) or -inf (!up); x finite. */
float nextFloat(float x, bool up) {
    if (x == 0.0f)
        return up ? std::numeric_limits<float>::denorm_min()
                  : -std::numeric_limits<float>::denorm_min();
    const uint32_t bits = std::bit_cast<uint32_t>(x);
    return std::bit_cast<float>((x > 0.0f) == up ? bits + 1 : bits - 1);
}

/** The spacing of floats at magnitude m (m >= 0, finite): 2^(exponent - 23), at least the
 *  smallest subnormal. */
float ulpAt(float m) {
    const uint32_t exponent = std::bit_cast<uint32_t>(m) & 0x7f800000u;
    return exponent > (23u << 23) ? std::bit_cast<float>(exponent - (23u << 23))
                                  : std::numeric_limits<float>::denorm_min();
}

/** Distance from p to the triangle (a, b, c) (Ericson, Real-Time Collision Detection, 5.1.5). */
double pointTriangleDistance(const glm::dvec3& p, const glm::dvec3& a, const glm::dvec3& b,
                             const glm::dvec3& c) {
    const glm::dvec3 ab = b - a, ac = c - a, ap = p - a;
    const double d1 = glm::dot(ab, ap), d2 = glm::dot(ac, ap);
    if (d1 <= 0.0 && d2 <= 0.0) return glm::length(p - a);
    const glm::dvec3 bp = p - b;
    const double d3 = glm::dot(ab, bp), d4 = glm::dot(ac, bp);
    if (d3 >= 0.0 && d4 <= d3) return glm::length(p - b);
    const double vc = d1 * d4 - d3 * d2;
    if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) return glm::length(p - (a + ab * (d1 / (d1 - d3))));
    const glm::dvec3 cp = p - c;
    const double d5 = glm::dot(ab, cp), d6 = glm::dot(ac, cp);
    if (d6 >= 0.0 && d5 <= d6) return glm::length(p - c);
    const double vb = d5 * d2 - d1 * d6;
    if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) return glm::length(p - (a + ac * (d2 / (d2 - d6))));
    const double va = d3 * d6 - d5 * d4;
    if (va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0)
        return glm::length(p - (b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)))));
    const double denom = 1.0 / (va + vb + vc);
    return glm::length(p - (a + ab * (vb * denom) + ac * (vc * denom)));
}

double longestEdgeOf(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c) {
    return std::max({glm::length(b - a), glm::length(c - b), glm::length(a - c)});
}

/** eps (1 + L l / (2 area)), capped: Embree's relative error of T's plane seen from distance L. */
double marginPerLength(double L, double l, double twiceArea) {
    const double shape = twiceArea > 0.0 ? std::min(kShapeCap, 1.0 + L * l / twiceArea) : kShapeCap;
    return kSafety * kEps * shape;
}

/** L = the largest distance from o to a vertex. */
double farthestVertex(const glm::dvec3& p0, const glm::dvec3& p1, const glm::dvec3& p2,
                      const glm::dvec3& o) {
    return std::sqrt(
        std::max({glm::dot(p0 - o, p0 - o), glm::dot(p1 - o, p1 - o), glm::dot(p2 - o, p2 - o)}));
}

float maxAbs(const glm::vec3& v) {
    return std::max({std::abs(v.x), std::abs(v.y), std::abs(v.z)});
}

/** Whether p is at least `inset` inside every edge line of `tri` (float; false for an
 *  infinite inset). */
bool insideBy(const MeshTriangle& tri, const glm::vec3& p, float inset) {
    if (!(inset < std::numeric_limits<float>::infinity())) return false;
    const glm::vec3 v[3] = {tri.p0, tri.p1, tri.p2};
    for (int i = 0; i < 3; ++i) {
        const glm::vec3 e = v[(i + 1) % 3] - v[i];
        const float s = glm::dot(glm::cross(e, p - v[i]), tri.n);  // distance x |e|
        if (!(s >= 0.0f) || s * s < inset * inset * glm::dot(e, e)) return false;
    }
    return true;
}

}  // namespace

glm::dvec3 exactHitPoint(const MeshTriangle& tri, const glm::vec3& o, const glm::vec3& d, float b1,
                         float b2) {
    const glm::dvec3 p0(tri.p0), p1(tri.p1), p2(tri.p2);
    const glm::dvec3 n = glm::cross(p1 - p0, p2 - p0);
    const glm::dvec3 O(o), D(d);
    const double den = glm::dot(n, D);
    if (std::abs(den) > 1e-4 * glm::length(n) * glm::length(D))
        return O + D * (glm::dot(n, p0 - O) / den);
    return p0 + double(b1) * (p1 - p0) + double(b2) * (p2 - p0);
}

double intersectionMargin(const MeshTriangle& tri, const glm::dvec3& o) {
    const glm::dvec3 p0(tri.p0), p1(tri.p1), p2(tri.p2);
    const double L = farthestVertex(p0, p1, p2, o);
    const double twiceArea = glm::length(glm::cross(p1 - p0, p2 - p0));
    return L * marginPerLength(L, longestEdgeOf(p0, p1, p2), twiceArea);
}

/** The constraints gathered for one origin. */
struct SpawnOffsets::Candidates {
    Plane planes[kMaxPlanes];
    int count = 0;
};

namespace {

/** A triangle in double: vertices, unit normal (counter-clockwise), longest edge, 2 x area. */
struct Tri {
    glm::dvec3 v[3];
    glm::dvec3 n{0.0};
    double longestEdge = 0.0;
    double twiceArea = 0.0;

    explicit Tri(const MeshTriangle& t) : v{glm::dvec3(t.p0), glm::dvec3(t.p1), glm::dvec3(t.p2)} {
        const glm::dvec3 e0 = v[1] - v[0], e1 = v[2] - v[1], e2 = v[0] - v[2];
        const glm::dvec3 c = glm::cross(e0, -e2);
        twiceArea = glm::length(c);
        if (twiceArea > 0.0) n = c * (1.0 / twiceArea);
        longestEdge = std::sqrt(std::max({glm::dot(e0, e0), glm::dot(e1, e1), glm::dot(e2, e2)}));
    }
    /** The largest margin T asks for at a point on or next to itself (L <= l there). */
    double ownMargin() const {
        return longestEdge * marginPerLength(longestEdge, longestEdge, twiceArea);
    }
    /** Whether p is at least `inset` inside every edge's line. */
    bool insideBy(const glm::dvec3& p, double inset) const {
        for (int i = 0; i < 3; ++i) {
            const glm::dvec3 e = v[(i + 1) % 3] - v[i];
            const double s = glm::dot(glm::cross(e, p - v[i]), n);  // distance x |e|
            if (!(s >= 0.0) || s * s < inset * inset * glm::dot(e, e)) return false;
        }
        return true;
    }
    /** The triangle shrunk by `inset` from every edge (homothety about the incentre); false
     *  when nothing is that far inside. */
    bool shrunk(double inset, Tri& out) const {
        const double a = glm::length(v[2] - v[1]), b = glm::length(v[0] - v[2]);
        const double c = glm::length(v[1] - v[0]);
        const double perimeter = a + b + c;
        if (!(twiceArea > 0.0) || !(perimeter > 0.0)) return false;
        const double inradius = twiceArea / perimeter;
        if (!(inradius > inset)) return false;
        const glm::dvec3 incentre = (a * v[0] + b * v[1] + c * v[2]) / perimeter;
        const double k = (inradius - inset) / inradius;
        out = *this;
        for (glm::dvec3& q : out.v)
            q = incentre + (q - incentre) * k;
        out.longestEdge *= k;
        out.twiceArea *= k * k;
        return true;
    }
};

/** Whether some axis separates X and T by more than r (then they are farther apart than r):
 *  the coordinate axes, both normals, and the in-plane normals of X's edges. */
bool separated(const Tri& X, const Tri& T, double r) {
    for (int k = 0; k < 3; ++k) {
        const double xlo = std::min({X.v[0][k], X.v[1][k], X.v[2][k]});
        const double xhi = std::max({X.v[0][k], X.v[1][k], X.v[2][k]});
        const double tlo = std::min({T.v[0][k], T.v[1][k], T.v[2][k]});
        const double thi = std::max({T.v[0][k], T.v[1][k], T.v[2][k]});
        if (tlo > xhi + r || thi < xlo - r) return true;
    }
    auto apart = [r](const glm::dvec3& axis, const Tri& a, const Tri& b) {
        const double o = glm::dot(axis, a.v[0]);
        double lo = std::numeric_limits<double>::infinity(), hi = -lo;
        for (const glm::dvec3& q : b.v) {
            lo = std::min(lo, glm::dot(axis, q) - o);
            hi = std::max(hi, glm::dot(axis, q) - o);
        }
        return lo > r || hi < -r;
    };
    if (apart(X.n, X, T) || apart(T.n, T, X)) return true;
    for (int i = 0; i < 3; ++i) {  // T wholly beyond one of X's edges
        const glm::dvec3 e = X.v[(i + 1) % 3] - X.v[i];
        const glm::dvec3 out = glm::normalize(glm::cross(e, X.n));  // away from X's inside
        double lo = std::numeric_limits<double>::infinity();
        for (const glm::dvec3& q : T.v)
            lo = std::min(lo, glm::dot(out, q - X.v[i]));
        if (lo > r) return true;
    }
    return false;
}

/** The box of the points of A within r of T: T clipped to the slab |dot(n_A, x) - d_A| <= r,
 *  its bounds widened by r, in float rounded outwards (a point of A within r of T has its
 *  nearest point of T in that slab). */
std::pair<glm::vec3, glm::vec3> contactBox(const Tri& A, const Tri& T, double r) {
    const double dA = glm::dot(A.n, A.v[0]);
    glm::dvec3 poly[9];
    int count = 0;
    for (int k = 0; k < 3; ++k)
        poly[count++] = T.v[k];
    // Sutherland-Hodgman against s <= r, then s >= -r (s: signed distance from A's plane)
    for (const double sign : {1.0, -1.0}) {
        glm::dvec3 out[9];
        int n = 0;
        for (int i = 0; i < count; ++i) {
            const glm::dvec3& a = poly[i];
            const glm::dvec3& b = poly[(i + 1) % count];
            const double sa = sign * (glm::dot(A.n, a) - dA) - r;
            const double sb = sign * (glm::dot(A.n, b) - dA) - r;
            if (sa <= 0.0) out[n++] = a;
            if ((sa < 0.0) != (sb < 0.0) && sa != sb && n < 9)
                out[n++] = a + (b - a) * (sa / (sa - sb));
        }
        count = n;
        std::copy(out, out + n, poly);
        if (count == 0) break;
    }
    glm::dvec3 lo(std::numeric_limits<double>::infinity()), hi(-lo);
    for (int i = 0; i < count; ++i) {
        lo = glm::min(lo, poly[i]);
        hi = glm::max(hi, poly[i]);
    }
    if (count == 0) lo = hi = T.v[0];  // (separated() let it through: keep a point box)
    glm::vec3 flo, fhi;
    for (int k = 0; k < 3; ++k) {
        const double pad = r + 1e-9 * std::max(std::abs(lo[k]), std::abs(hi[k]));
        flo[k] = nextFloat(float(lo[k] - pad), false);
        fhi[k] = nextFloat(float(hi[k] + pad), true);
    }
    return {flo, fhi};
}

}  // namespace

SpawnOffsets::SpawnOffsets(const EmbreeScene& mesh) : m_mesh(mesh) {
    const size_t n = mesh.triangleCount();
    m_reach.assign(n, 0.0);
    m_info.assign(n, TriangleInfo{});
    float largestCoordinate = 0.0f;
    for (size_t t = 0; t < n; ++t) {
        const MeshTriangle& tri = mesh.triangle(uint32_t(t));
        largestCoordinate =
            std::max({largestCoordinate, maxAbs(tri.p0), maxAbs(tri.p1), maxAbs(tri.p2)});
        if (!(tri.area > 0.0f)) continue;
        const double margin = Tri(tri).ownMargin();
        const Tri shape(tri);
        m_info[t].edgeOverArea = float(shape.longestEdge / shape.twiceArea);
        m_reach[t] = 2.0 * margin;
        m_largestMargin = std::max(m_largestMargin, margin);
    }
    m_slack = 2.0 * ulpAt(largestCoordinate);
    for (double& r : m_reach)
        r += m_slack;
    buildNeighbours();
}

void SpawnOffsets::buildNeighbours() {
    const size_t n = m_mesh.triangleCount();
    std::vector<std::vector<Neighbour>> lists(n);
    std::vector<uint8_t> overflow(n, 0);
    const double largestReach = 2.0 * m_largestMargin + m_slack;
    tbb::parallel_for(size_t(0), n, [&](size_t a) {
        const MeshTriangle& A = m_mesh.triangle(uint32_t(a));
        if (!(A.area > 0.0f)) return;
        const Tri ta(A);
        const glm::vec3 lo = glm::min(A.p0, glm::min(A.p1, A.p2));
        const glm::vec3 hi = glm::max(A.p0, glm::max(A.p1, A.p2));
        const glm::vec3 centre = 0.5f * (lo + hi);
        const float radius =
            0.5f * glm::length(hi - lo) * (1.0f + 1e-6f) + float(2.0 * largestReach);
        std::vector<Neighbour>& list = lists[a];
        std::vector<uint32_t> near;
        double widest = m_reach[a];
        m_mesh.forEachNearby(centre, radius, [&](uint32_t t) {
            if (t == a || overflow[a]) return;
            const MeshTriangle& T = m_mesh.triangle(t);
            if (!(T.area > 0.0f)) return;
            if (separated(ta, Tri(T), std::max(m_reach[a], m_reach[t]))) return;
            if (near.size() == kMaxNeighbours) {
                overflow[a] = 1;
                return;
            }
            near.push_back(t);
            widest = std::max(widest, m_reach[t]);
        });
        if (overflow[a]) return;
        // Hits at least `inset` inside every edge see only the neighbours that reach the
        // shrunk triangle (contacts, overlaps): list those first
        const double inset = 2.0 * widest;
        Tri inner = ta;
        const bool hasInterior = ta.shrunk(inset, inner);
        std::stable_partition(near.begin(), near.end(), [&](uint32_t t) {
            return hasInterior &&
                   !separated(inner, Tri(m_mesh.triangle(t)), std::max(m_reach[a], m_reach[t]));
        });
        for (uint32_t t : near) {
            const Tri tt(m_mesh.triangle(t));
            const auto [lo, hi] = contactBox(ta, tt, std::max(m_reach[a], m_reach[t]));
            list.push_back({lo, hi, t});
            if (hasInterior && !separated(inner, tt, std::max(m_reach[a], m_reach[t])))
                ++m_info[a].interior;
        }
        m_info[a].inset = hasInterior ? float(inset) : std::numeric_limits<float>::infinity();
    });
    uint32_t total = 0;
    for (size_t a = 0; a < n; ++a) {
        m_info[a].first = total;
        m_info[a].count = overflow[a] ? kOverflow : uint16_t(lists[a].size());
        total += uint32_t(lists[a].size());
    }
    m_neighbours.reserve(total);
    for (std::vector<Neighbour>& list : lists)
        m_neighbours.insert(m_neighbours.end(), list.begin(), list.end());
    m_xRange.reserve(total);
    for (const Neighbour& nb : m_neighbours)
        m_xRange.emplace_back(nb.lo.x, nb.hi.x);
}

size_t SpawnOffsets::neighbourCount(uint32_t prim) const {
    return m_info[prim].count == kOverflow ? 0 : m_info[prim].count;
}

size_t SpawnOffsets::interiorNeighbourCount(uint32_t prim) const {
    return m_info[prim].interior;
}

namespace {

/** Adds t's constraint if p is within its margin (`onIt`: p is a point of t, no need to ask). */
void addConstraint(const Tri& t, const glm::dvec3& p, const glm::dvec3& toward, double slack,
                   bool onIt, SpawnOffsets::Candidates& out) {
    if (!(t.twiceArea > 0.0)) return;  // Embree never reports a zero-area triangle
    const double L = farthestVertex(t.v[0], t.v[1], t.v[2], p);
    const double margin = L * marginPerLength(L, t.longestEdge, t.twiceArea);
    glm::dvec3 n = t.n;
    if (!onIt) {
        if (std::abs(glm::dot(n, p - t.v[0])) > margin + slack) return;
        if (pointTriangleDistance(p, t.v[0], t.v[1], t.v[2]) > margin + slack) return;
    }
    // The side the path is on: towards `toward`; for a ray along the plane, where p lies
    double side = glm::dot(n, toward);
    if (side == 0.0) side = glm::dot(n, p - t.v[0]);
    if (side < 0.0) n = -n;
    if (out.count < kMaxPlanes) out.planes[out.count++] = {n, glm::dot(n, t.v[0]), margin};
}

}  // namespace

glm::vec3 SpawnOffsets::origin(const glm::dvec3& p, uint32_t prim, const glm::vec3& toward) const {
    const MeshTriangle& tri = m_mesh.triangle(prim);
    const glm::vec3 pf(p);
    const glm::vec3 ulps =
        glm::vec3(ulpAt(std::abs(pf.x)), ulpAt(std::abs(pf.y)), ulpAt(std::abs(pf.z)));
    const float magnitude = maxAbs(pf);

    // The neighbours that could be within reach: none when the point is deep inside its
    // triangle and nothing touches the triangle's inside (most hits), quick float rejections
    uint32_t near[kMaxPlanes];
    int nearCount = 0;
    const TriangleInfo info = m_info[prim];
    const bool overflow = info.count == kOverflow;
    if (!overflow) {
        uint32_t end = info.first + info.count;
        const uint32_t interiorEnd = info.first + info.interior;
        if (end > interiorEnd && insideBy(tri, pf, info.inset + 4.0f * magnitude * 0x1p-24f))
            end = interiorEnd;
        // p may sit a few float steps off its triangle: widen every box by that
        const glm::vec3 tolerance = 4.0f * ulps + 2e-7f * magnitude;
        for (uint32_t i = info.first; i < end && nearCount < kMaxPlanes; ++i) {
            const glm::vec2 x = m_xRange[i];
            if (pf.x < x.x - tolerance.x || pf.x > x.y + tolerance.x) continue;
            const Neighbour& nb = m_neighbours[i];
            if (glm::any(glm::lessThan(pf, nb.lo - tolerance)) ||
                glm::any(glm::greaterThan(pf, nb.hi + tolerance)))
                continue;
            near[nearCount++] = nb.prim;
        }
        if (nearCount == 0) {
            // Only the point's own plane: push along its (float) normal by the triangle's own
            // margin (L <= its longest edge here) and enough float steps that neither p's
            // rounding nor o's can undo it; no check needed
            const glm::vec3 n = glm::dot(tri.n, toward) >= 0.0f ? tri.n : -tri.n;
            const double L =
                farthestVertex(glm::dvec3(tri.p0), glm::dvec3(tri.p1), glm::dvec3(tri.p2), p);
            const double margin =
                L * kSafety * kEps * std::min(kShapeCap, 1.0 + L * double(info.edgeOverArea));
            const double push = margin * (1.0 + 1e-5) + 4.0 * double(glm::dot(glm::abs(n), ulps));
            return glm::vec3(p + glm::dvec3(n) * push);
        }
    }

    // The general case, in double: every plane within reach, measured exactly
    // Rounding moves the point by up to an ulp per coordinate: triangles that close count as
    // touching it
    const double slack = 2.0 * ulpAt(magnitude);
    const glm::dvec3 w(toward);
    Candidates c;
    addConstraint(Tri(tri), p, w, slack, true, c);
    if (overflow) {
        const float radius = float(2.0 * m_largestMargin + 2.0 * slack);
        m_mesh.forEachNearby(pf, radius, [&](uint32_t t) {
            if (t != prim) addConstraint(Tri(m_mesh.triangle(t)), p, w, slack, false, c);
        });
    }
    for (int i = 0; i < nearCount; ++i)
        addConstraint(Tri(m_mesh.triangle(near[i])), p, w, slack, false, c);

    // Project onto each violated half-space in turn (they all contain the free side), further
    // by what rounding to float can undo along n: half an ulp per coordinate (one, to be safe)
    glm::dvec3 o = p;
    for (int round = 0; round < kProjectRounds; ++round) {
        bool met = true;
        for (int i = 0; i < c.count; ++i) {
            const Plane& pl = c.planes[i];
            const double s = glm::dot(pl.n, o) - pl.d;
            if (s < pl.margin) {
                const double rounding = glm::dot(glm::abs(pl.n), glm::dvec3(ulps));
                o += pl.n * ((pl.margin - s) * (1.0 + 1e-6) + rounding);
                met = false;
            }
        }
        if (met) break;
    }

    // Round once; should a moved coordinate have crossed a power of two (coarser ulps), nudge
    // by ulps until every margin holds for the float point itself
    glm::vec3 of(o);
    for (int round = 0; round < kNudgeRounds; ++round) {
        glm::dvec3 push(0.0);
        const glm::dvec3 od(of);
        for (int i = 0; i < c.count; ++i) {
            const Plane& pl = c.planes[i];
            if (glm::dot(pl.n, od) - pl.d < pl.margin) push += pl.n;
        }
        if (push == glm::dvec3(0.0)) break;
        for (int k = 0; k < 3; ++k) {
            if (push[k] != 0.0) of[k] = nextFloat(of[k], push[k] > 0.0);
        }
    }
    return of;
}

}  // namespace gilab::ref
