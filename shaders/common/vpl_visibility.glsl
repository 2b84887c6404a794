// Clustered visibility through the paraboloid maps (Dong et al. 2009; Aranha et al. §III-C;
// docs/vpl.md "Gathering"). Include after declaring `clusters` (VplCluster[]) and `mapPosition`
// (image2DArray, rgba32f: xyz position, w radial distance). Used by the gather
// (common/vpl_gather.comp) and by ssvp's member test (ssvp/map_members.comp).
#ifndef GILAB_VPL_VISIBILITY_GLSL
#define GILAB_VPL_VISIBILITY_GLSL

// Is p (normal n) seen from the eye of map `layer`? res: map texels per side; biasTexels: the
// distance tolerance in map texels at p.
float vplMapVisible(vec3 p, vec3 n, int layer, uint res, float biasTexels) {
    VplCluster c = clusters[layer];
    if (c.position.w < 0.5) return 0.0;
    mat3 frame = vplFrame(c.normal.xyz);
    vec3 local = frame * (p - c.position.xyz);
    float dist = length(local);
    if (!(dist > 0.0)) return 1.0;
    float r = float(res);
    // Texel size at p: angular width 4 / (res (1 + r^2)) of the map at its disk point.
    vec2 q = vplParaboloidProject(local / dist);
    float texel = dist * 4.0 / (r * (1.0 + dot(q, q)));
    // Move the receiver one texel along its normal (self-shadowing of the receiving surface).
    local = frame * (p + n * texel - c.position.xyz);
    if (local.z <= 0.0) return 0.0;  // behind the cluster: outside its hemisphere
    dist = length(local);
    q = vplParaboloidProject(local / dist);
    ivec2 t = clamp(ivec2(vplParaboloidUv(q) * r), ivec2(0), ivec2(int(r) - 1));
    float stored = imageLoad(mapPosition, ivec3(t, layer)).w;
    if (stored <= 0.0) return 1.0;  // nothing in that direction
    float cosRecv = abs(dot(n, local / dist));
    float bias = biasTexels * texel / max(cosRecv, 0.2);
    return dist <= stored + bias ? 1.0 : 0.0;
}

#endif  // GILAB_VPL_VISIBILITY_GLSL
