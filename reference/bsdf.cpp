#include "reference/bsdf.h"

#include <algorithm>
#include <cmath>

#include "core/image/color.h"
#include "reference/sampling.h"

namespace gilab::ref {
namespace {

// glTF 2.0 Appendix B.3.3: Trowbridge-Reitz / GGX distribution (Heaviside on n.h).
float dGgx(float nh, float alpha) {
    if (nh <= 0.0f) return 0.0f;
    const float a2 = alpha * alpha;
    const float d = nh * nh * (a2 - 1.0f) + 1.0f;
    return a2 / (kPi * d * d);
}

// glTF 2.0 Appendix B.3.2: height-correlated Smith visibility V = G / (4 |n.l| |n.v|).
float vSmithGgxCorrelated(float nl, float nv, float alpha) {
    const float a2 = alpha * alpha;
    const float gv = nl * std::sqrt(nv * nv * (1.0f - a2) + a2);
    const float gl = nv * std::sqrt(nl * nl * (1.0f - a2) + a2);
    const float denom = gv + gl;
    return denom > 0.0f ? 0.5f / denom : 0.0f;
}

// glTF 2.0 Appendix B.3.4: Schlick's Fresnel.
glm::vec3 fresnelSchlick(const glm::vec3& f0, float vh) {
    const float m = std::clamp(1.0f - std::abs(vh), 0.0f, 1.0f);
    const float m2 = m * m;
    return f0 + (glm::vec3(1.0f) - f0) * (m2 * m2 * m);
}

// Smith masking of GGX for one direction: G1 = 2 cos / (cos + sqrt(a^2 + (1 - a^2) cos^2))
// (Heitz 2014, "Understanding the Masking-Shadowing Function", Eq. 72 rewritten).
float g1Ggx(float cosTheta, float alpha) {
    const float a2 = alpha * alpha;
    return 2.0f * cosTheta / (cosTheta + std::sqrt(a2 + (1.0f - a2) * cosTheta * cosTheta));
}

// Heitz 2018, "Sampling the GGX Distribution of Visible Normals", listing 1 (isotropic alpha):
// a microfacet normal distributed as D_wo(h) = G1(wo) max(0, wo.h) D(h) / wo.z, wo.z > 0.
glm::vec3 sampleGgxVisibleNormal(const glm::vec3& wo, float alpha, glm::vec2 u) {
    const glm::vec3 vh = glm::normalize(glm::vec3(alpha * wo.x, alpha * wo.y, wo.z));
    const float lensq = vh.x * vh.x + vh.y * vh.y;
    const glm::vec3 t1 =
        lensq > 0.0f ? glm::vec3(-vh.y, vh.x, 0.0f) / std::sqrt(lensq) : glm::vec3(1, 0, 0);
    const glm::vec3 t2 = glm::cross(vh, t1);
    const float r = std::sqrt(u.x);
    const float phi = 2.0f * kPi * u.y;
    const float p1 = r * std::cos(phi);
    float p2 = r * std::sin(phi);
    const float s = 0.5f * (1.0f + vh.z);
    p2 = (1.0f - s) * std::sqrt(std::max(0.0f, 1.0f - p1 * p1)) + s * p2;
    const glm::vec3 nh =
        p1 * t1 + p2 * t2 + std::sqrt(std::max(0.0f, 1.0f - p1 * p1 - p2 * p2)) * vh;
    return glm::normalize(glm::vec3(alpha * nh.x, alpha * nh.y, std::max(1e-6f, nh.z)));
}

}  // namespace

glm::vec3 evalGltfBrdf(const glm::vec3& n, const glm::vec3& l, const glm::vec3& v,
                       const glm::vec3& albedo, float metallic, float roughness) {
    const float nl = glm::dot(n, l);
    if (nl <= 0.0f) return glm::vec3(0.0f);
    const glm::vec3 diffuse = albedo * kInvPi;
    if (!(metallic > 0.0f || roughness < 1.0f)) return diffuse;

    const float nv = std::abs(glm::dot(n, v));
    const glm::vec3 hUnnorm = l + v;
    const float hLen = glm::length(hUnnorm);
    if (hLen <= 0.0f) return (1.0f - metallic) * diffuse;  // l == -v: no half vector
    const glm::vec3 h = hUnnorm / hLen;
    const float vh = glm::dot(v, h);
    const float lh = glm::dot(l, h);
    if (vh <= 0.0f || lh <= 0.0f) return (1.0f - metallic) * diffuse;  // Heaviside of B.3.2

    const float alpha = std::max(roughness * roughness, kBrdfMinAlpha);
    const float specular = vSmithGgxCorrelated(nl, nv, alpha) * dGgx(glm::dot(n, h), alpha);
    const glm::vec3 fDielectric = fresnelSchlick(glm::vec3(0.04f), vh);
    const glm::vec3 fMetal = fresnelSchlick(albedo, vh);
    const glm::vec3 dielectric = (glm::vec3(1.0f) - fDielectric) * diffuse + fDielectric * specular;
    const glm::vec3 metal = fMetal * specular;
    return dielectric * (1.0f - metallic) + metal * metallic;  // GLSL mix()
}

Bsdf::Bsdf(const glm::vec3& n, const glm::vec3& albedo, float metallic, float roughness)
    : m_n(n),
      m_albedo(albedo),
      m_metallic(metallic),
      m_roughness(roughness),
      m_alpha(std::max(roughness * roughness, kBrdfMinAlpha)),
      m_glossy(metallic > 0.0f || roughness < 1.0f) {}

float Bsdf::specularProbability(const glm::vec3& wo) const {
    if (!m_glossy) return 0.0f;
    const float nv = glm::dot(m_n, wo);
    if (!(nv > 0.0f)) return 0.0f;  // VNDF sampling needs wo above the shading normal
    // Lobe weights: the Fresnel-weighted reflectance of each lobe at normal incidence of wo
    const float fd = fresnelSchlick(glm::vec3(0.04f), nv).x;
    const float fm = luminance(fresnelSchlick(m_albedo, nv));
    const float wSpec = (1.0f - m_metallic) * fd + m_metallic * fm;
    const float wDiff = (1.0f - m_metallic) * (1.0f - fd) * luminance(m_albedo);
    if (!(wDiff > 0.0f)) return 1.0f;
    if (!(wSpec > 0.0f)) return 0.0f;
    // Keep both lobes at >= 10% so neither part of the BRDF is ever undersampled
    return std::clamp(wSpec / (wSpec + wDiff), 0.1f, 0.9f);
}

float Bsdf::pdfGgxVisible(const glm::vec3& wo, const glm::vec3& wi) const {
    // pdf(wi) = D_wo(h) / (4 wo.h) = G1(wo) D(h) / (4 n.wo) (Heitz 2018, Eq. 17 + reflection
    // Jacobian); h computed exactly as in evalGltfBrdf so D cancels in f / pdf.
    const float nv = glm::dot(m_n, wo);
    if (!(nv > 0.0f)) return 0.0f;
    const glm::vec3 hUnnorm = wi + wo;
    const float hLen = glm::length(hUnnorm);
    if (!(hLen > 0.0f)) return 0.0f;
    const glm::vec3 h = hUnnorm / hLen;
    if (!(glm::dot(wo, h) > 0.0f)) return 0.0f;
    return g1Ggx(nv, m_alpha) * dGgx(glm::dot(m_n, h), m_alpha) / (4.0f * nv);
}

float Bsdf::pdf(const glm::vec3& wo, const glm::vec3& wi) const {
    const float cosI = glm::dot(m_n, wi);
    const float pdfDiffuse = cosI > 0.0f ? cosI * kInvPi : 0.0f;
    const float pSpec = specularProbability(wo);
    if (pSpec <= 0.0f) return pdfDiffuse;
    return (1.0f - pSpec) * pdfDiffuse + pSpec * pdfGgxVisible(wo, wi);
}

bool Bsdf::sample(const glm::vec3& wo, float uLobe, glm::vec2 u, BsdfSample& out) const {
    const Frame frame = Frame::fromZ(m_n);
    if (!m_glossy) {
        // Lambertian: what the general path below computes when pSpec = 0 (the cosine lobe,
        // pdf() = cos / pi, eval() = albedo / pi), without its calls: bit-identical, cheaper
        out.wi = glm::normalize(frame.toWorld(sampleCosineHemisphere(u)));
        const float cosI = glm::dot(m_n, out.wi);
        out.pdf = cosI > 0.0f ? cosI * kInvPi : 0.0f;
        if (!(out.pdf > 0.0f)) return false;
        out.f = m_albedo * kInvPi;
        return true;
    }
    const float pSpec = specularProbability(wo);
    if (uLobe < pSpec) {
        const glm::vec3 woLocal = frame.toLocal(wo);
        const glm::vec3 h = sampleGgxVisibleNormal(woLocal, m_alpha, u);
        const glm::vec3 wiLocal = 2.0f * glm::dot(woLocal, h) * h - woLocal;  // reflect
        if (!(wiLocal.z > 0.0f)) return false;
        out.wi = glm::normalize(frame.toWorld(wiLocal));
    } else {
        out.wi = glm::normalize(frame.toWorld(sampleCosineHemisphere(u)));
    }
    out.pdf = pdf(wo, out.wi);
    if (!(out.pdf > 0.0f)) return false;
    out.f = eval(wo, out.wi);
    return true;
}

}  // namespace gilab::ref
