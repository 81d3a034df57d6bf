// The layers glTF stacks over the metallic-roughness base (KHR_materials_sheen, then
// KHR_materials_clearcoat on top), as lobe functions both renderer families evaluate:
//   f = (f_base * (1 - max(sheenColor) E_sheen) + f_sheen) * (1 - clearcoat F_coat) + clearcoat f_coat
// with E_sheen the sheen lobe's directional albedo (so adding sheen does not add energy) and
// F_coat the coat's Fresnel term (ior 1.5). Cosines are taken against each layer's own normal.
#pragma once

namespace pr::scene {

// Charlie sheen (Estevez & Kulla 2017, as the KHR_materials_sheen spec gives it):
// D(h) = (2 + 1/a) sin(theta_h)^(1/a) / (2 pi), a = roughness^2 (clamped away from 0), with
// the Ashikhmin visibility V = 1 / (4 (NdotL + NdotV - NdotL NdotV)). sheenLobe = D V,
// to be multiplied by sheenColor; cosines in (0, 1].
float sheenLobe(float roughness, float NdotH, float NdotL, float NdotV);
// Directional albedo of sheenLobe: integral of D V NdotL over the hemisphere for view cosine
// NdotV, from a table integrated numerically on first use (bilinear in NdotV and roughness).
float sheenAlbedo(float roughness, float NdotV);

// Fresnel of the clear coat (dielectric, ior 1.5: F0 = 0.04), Schlick.
float coatFresnel(float cosTheta);
// The coat's GGX lobe D G F / (4 NdotL NdotV) with alpha = roughness^2 (Smith G, Walter et
// al. 2007), F = coatFresnel(VdotH); the clearcoat factor is applied by the caller.
float coatLobe(float roughness, float NdotH, float NdotL, float NdotV, float VdotH);
// The GGX alpha a coat of this roughness uses (roughness^2, kept above a pixel-sized spike).
float coatAlpha(float roughness);

}  // namespace pr::scene
