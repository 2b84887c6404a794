// Dense photon splat (notes 001 §2.5 step 2), one thread per photon of one light (all views of a
// point light or emitter sample, or a spot's / directional light's map), in two modes:
//
// INJECT_MODE_COUNT: (1) the photon's flux is added to the voxel that holds it (the flux planes,
//   a diagnostic: their sum is the injected flux). A photon lies on a voxelized surface, so its
//   voxel is covered; round-off at a voxel face can put it in the empty neighbour, so an empty
//   voxel is retried half a voxel toward and away from the light. (2) The photon's footprint (its
//   texel projected onto the surface's tangent plane: a parallelogram, long at grazing incidence)
//   is cut into kx x ky cells of at most v0/2 per side; every covered voxel that the tangent
//   plane crosses within a cell's half-diagonal of a cell centre counts one deposit.
// INJECT_MODE_IRRADIANCE: the same deposits each add E / count (E the photon's irradiance), so
//   every voxel ends up with this light's mean irradiance over the deposits it received, summed
//   over the lights. The count plane is cleared before each light.
// With float accumulation the count is an area: each deposit weighs its footprint cell's area
//   and adds E w / W (W the voxel's summed area), the area-weighted mean irradiance, i.e. the
//   deposited flux over the deposited area. A plain mean over deposits weighs E by the photon
//   density, which grows with E near a light (E^2-weighted: 115x the reference's indirect light
//   for a spot 1 mm from a wall, found by `gilab audit`); the fixed-point fallback keeps counts.
//
// Averaging E instead of dividing the summed flux by the voxel's cross-section v0^2 is exact for
// a plane at any orientation (the surface area inside a voxel does not matter), and the footprint
// cells reach every voxel the plane crosses, even where it only clips a corner. Photons whose
// surface faces away from the light (normal.w = 0) and misses deposit nothing.
#include "inject_common.glsl"
#include "photon_footprint.glsl"

layout(local_size_x = 64) in;


bool covered(ivec3 c) {
    return voxelInside(pc.grid, c) && texelFetch(voxelAlbedoOpacity, c, 0).a > 0.0;
}

void addFlux(uint index, vec3 flux) {
#ifdef INJECT_FIXED_POINT
    uvec3 q = uvec3(round(flux * pc.scale.x));
    if (q.r != 0u) atomicAdd(fluxPlanes[0].v[index], q.r);
    if (q.g != 0u) atomicAdd(fluxPlanes[1].v[index], q.g);
    if (q.b != 0u) atomicAdd(fluxPlanes[2].v[index], q.b);
#else
    if (flux.r != 0.0) atomicAdd(fluxPlanes[0].v[index], flux.r);
    if (flux.g != 0.0) atomicAdd(fluxPlanes[1].v[index], flux.g);
    if (flux.b != 0.0) atomicAdd(fluxPlanes[2].v[index], flux.b);
#endif
}

void addIrradiance(uint index, vec3 e) {
#ifdef INJECT_FIXED_POINT
    uvec3 q = uvec3(round(e * pc.scale.z));
    if (q.r != 0u) atomicAdd(irradiancePlanes[0].v[index], q.r);
    if (q.g != 0u) atomicAdd(irradiancePlanes[1].v[index], q.g);
    if (q.b != 0u) atomicAdd(irradiancePlanes[2].v[index], q.b);
#else
    if (e.r != 0.0) atomicAdd(irradiancePlanes[0].v[index], e.r);
    if (e.g != 0.0) atomicAdd(irradiancePlanes[1].v[index], e.g);
    if (e.b != 0.0) atomicAdd(irradiancePlanes[2].v[index], e.b);
#endif
}

void splatFlux(Photon p, float v0) {
    ivec3 c = voxelCoordOf(pc.grid, p.positionValid.xyz);
    if (!covered(c)) {
        ivec3 toward = voxelCoordOf(pc.grid, p.positionValid.xyz + 0.5 * v0 * p.toLight.xyz);
        ivec3 away = voxelCoordOf(pc.grid, p.positionValid.xyz - 0.5 * v0 * p.toLight.xyz);
        c = covered(toward) ? toward : (covered(away) ? away : c);
    }
    if (!voxelInside(pc.grid, c)) return;
    addFlux(voxelLinearIndex(pc.grid, c), max(p.flux.rgb, vec3(0.0)));
}

// Deposits at world point q (on the tangent plane of normal n) into every covered voxel that the
// plane crosses within distance r of q (r <= v0 / 2: at most 2 voxels per axis).
void deposit(vec3 q, vec3 n, float r, vec3 e, float area) {
    vec3 g = voxelWorldToGrid(pc.grid, q);
    float rg = r / voxelSize(pc.grid);
    ivec3 lo = ivec3(floor(g - rg));
    ivec3 hi = ivec3(floor(g + rg));
    for (int z = lo.z; z <= hi.z; ++z) {
        for (int y = lo.y; y <= hi.y; ++y) {
            for (int x = lo.x; x <= hi.x; ++x) {
                ivec3 c = ivec3(x, y, z);
                if (!covered(c) || !footprintTouchesVoxel(c, g, n, rg)) continue;
                uint index = voxelLinearIndex(pc.grid, c);
#ifdef INJECT_FIXED_POINT
                if (pc.counts.z == INJECT_MODE_COUNT) {
                    atomicAdd(photonCount[index], 1u);
                } else {
                    uint count = photonCount[index];
                    if (count > 0u) addIrradiance(index, e / float(count));
                }
#else
                if (pc.counts.z == INJECT_MODE_COUNT) {
                    atomicAdd(depositArea[index], area);
                } else {
                    float total = depositArea[index];
                    if (total > 0.0) addIrradiance(index, e * (area / total));
                }
#endif
            }
        }
    }
}

void main() {
    uint k = gl_GlobalInvocationID.x;
    if (k >= pc.counts.x) return;
    uint i = pc.counts.y + k;
    Photon p = photons[i];
    if (p.positionValid.w < 0.5) return;
    float v0 = voxelSize(pc.grid);
    if (pc.counts.z == INJECT_MODE_COUNT) splatFlux(p, v0);
    if (p.normal.w < 0.5) return;  // faces away from the light: carries nothing

    // The photon's view and texel
    uint v = pc.light.x;
    for (uint j = pc.light.x; j < pc.light.x + pc.light.y; ++j) {
        v = j;
        if (i < views[j].texels.z + views[j].texels.x * views[j].texels.y) break;
    }
    LightView view = views[v];
    uint t = i - view.texels.z;
    uvec2 res = view.texels.xy;
    vec2 ndc = (vec2(t % res.x, t / res.x) + 0.5) / vec2(res) * 2.0 - 1.0;

    // Footprint edges on the tangent plane: d(hit)/d(ndc) times the texel's ndc size
    vec3 n = p.normal.xyz;
    vec3 x = p.positionValid.xyz;
    vec3 ex, ey;
    if (view.positionKind.w > 0.5) {
        vec3 f = view.forward.xyz;
        float nf = dot(n, f);
        if (abs(nf) < 1e-8) nf = -1e-8;
        ex = view.axisX.xyz - f * (dot(n, view.axisX.xyz) / nf);
        ey = view.axisY.xyz - f * (dot(n, view.axisY.xyz) / nf);
    } else {
        vec3 ray = view.forward.xyz + ndc.x * view.axisX.xyz + ndc.y * view.axisY.xyz;
        float dist = dot(x - view.positionKind.xyz, ray) / dot(ray, ray);
        float nr = dot(n, ray);
        if (abs(nr) < 1e-8) nr = -1e-8;
        ex = dist * (view.axisX.xyz - ray * (dot(n, view.axisX.xyz) / nr));
        ey = dist * (view.axisY.xyz - ray * (dot(n, view.axisY.xyz) / nr));
    }
    ex *= 2.0 / float(res.x);
    ey *= 2.0 / float(res.y);
    FootprintCells cells = footprintCells(ex, ey, v0);

    vec3 e = max(p.irradiance.rgb, vec3(0.0));
#ifdef INJECT_FIXED_POINT
    e = min(e, vec3(pc.params.x));
#endif
    float area = footprintCellArea(cells);
    for (int b = 0; b < cells.ky; ++b)
        for (int a = 0; a < cells.kx; ++a)
            deposit(x + footprintCellOffset(cells, a, b), n, cells.radius, e, area);
}
