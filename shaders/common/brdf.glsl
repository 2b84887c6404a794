// The one BRDF of the project (docs/shared_passes.md, "BRDF"). The CPU path tracer implements
// exactly the same formulas; keep both in step.
//
// - Non-glossy materials (metallic == 0 and roughness == 1): Lambertian, albedo / pi.
// - Glossy materials: glTF 2.0 specification, Appendix B "BRDF Implementation":
//     f = mix(dielectric, metal, metallic)
//     dielectric = (1 - F_d) * albedo / pi + F_d * specular,   F_d = F(F0 = 0.04)
//     metal      = F_m * specular,                             F_m = F(F0 = albedo)
//     F          = F0 + (1 - F0) * (1 - |v.h|)^5               (Schlick)
//     specular   = V_SmithGGXCorrelated * D_GGX,               alpha = roughness^2
//   (Appendix B.3.2-B.3.5; V already contains the 1 / (4 |n.l| |n.v|) of the microfacet model.)
// - alpha is clamped to >= BRDF_MIN_ALPHA so a roughness of 0 stays finite (a delta lobe cannot
//   be shaded from point lights); the path tracer uses the same clamp.
#ifndef GILAB_BRDF_GLSL
#define GILAB_BRDF_GLSL

#define BRDF_PI 3.14159265358979323846
#define BRDF_MIN_ALPHA 1.0e-3

// glTF Appendix B.3.3: Trowbridge-Reitz / GGX normal distribution (with the Heaviside on n.h).
float brdfDGgx(float nh, float alpha) {
    if (nh <= 0.0) return 0.0;
    float a2 = alpha * alpha;
    float d = nh * nh * (a2 - 1.0) + 1.0;
    return a2 / (BRDF_PI * d * d);
}

// glTF Appendix B.3.2: height-correlated Smith visibility, V = G / (4 |n.l| |n.v|).
float brdfVSmithGgxCorrelated(float nl, float nv, float alpha) {
    float a2 = alpha * alpha;
    float gv = nl * sqrt(nv * nv * (1.0 - a2) + a2);
    float gl = nv * sqrt(nl * nl * (1.0 - a2) + a2);
    float denom = gv + gl;
    return denom > 0.0 ? 0.5 / denom : 0.0;
}

// glTF Appendix B.3.4: Schlick's Fresnel approximation.
vec3 brdfFresnelSchlick(vec3 f0, float vh) {
    float m = clamp(1.0 - abs(vh), 0.0, 1.0);
    float m2 = m * m;
    return f0 + (vec3(1.0) - f0) * (m2 * m2 * m);
}

bool brdfIsGlossy(float metallic, float roughness) { return metallic > 0.0 || roughness < 1.0; }

// f(wi, wo) for unit n, l = wi (toward the light), v = wo (toward the viewer).
// Returns 0 when the light is below the surface (n.l <= 0). No cosine factor.
vec3 evalBrdf(vec3 n, vec3 l, vec3 v, vec3 albedo, float metallic, float roughness) {
    float nl = dot(n, l);
    if (nl <= 0.0) return vec3(0.0);
    vec3 diffuse = albedo * (1.0 / BRDF_PI);
    if (!brdfIsGlossy(metallic, roughness)) return diffuse;

    float nv = abs(dot(n, v));
    vec3 hUnnorm = l + v;
    float hLen = length(hUnnorm);
    if (hLen <= 0.0) return (1.0 - metallic) * diffuse;  // l == -v: no half vector
    vec3 h = hUnnorm / hLen;
    float vh = dot(v, h);
    float lh = dot(l, h);
    if (vh <= 0.0 || lh <= 0.0) return (1.0 - metallic) * diffuse;  // Heaviside terms of B.3.2

    float alpha = max(roughness * roughness, BRDF_MIN_ALPHA);
    float specular = brdfVSmithGgxCorrelated(nl, nv, alpha) * brdfDGgx(dot(n, h), alpha);
    vec3 fDielectric = brdfFresnelSchlick(vec3(0.04), vh);
    vec3 fMetal = brdfFresnelSchlick(albedo, vh);
    vec3 dielectric = (vec3(1.0) - fDielectric) * diffuse + fDielectric * specular;
    vec3 metal = fMetal * specular;
    return mix(dielectric, metal, metallic);
}

#endif  // GILAB_BRDF_GLSL
