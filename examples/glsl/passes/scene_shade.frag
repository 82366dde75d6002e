#version 450 core
// Built-in scenes, lit pass: Lambert with a standard shadow map (3x3 PCF) plus ambient, plus up to four
// spot lights (intensity x the smooth cone falloff / d^2, each with its perspective shadow map, 3x3 PCF),
// the sun optionally through its light texture.
layout(location = 0) in vec3 worldPosition;
layout(location = 1) in vec3 worldNormal;
layout(location = 1) uniform mat4 shadowClipFromWorld;
layout(location = 2) uniform vec3 lightDirection; // direction the light travels
layout(location = 3) uniform vec3 lightIrradiance;
layout(location = 4) uniform vec3 ambient;
layout(location = 5) uniform vec3 albedo;
layout(binding = 0) uniform sampler2DShadow shadowMap;
#define MAX_SPOTS 4
layout(location = 6) uniform int spotCount;
layout(location = 7) uniform vec3 spotPosition[MAX_SPOTS];
layout(location = 11) uniform vec3 spotAxis[MAX_SPOTS];
layout(location = 15) uniform vec2 spotCone[MAX_SPOTS]; // cos inner, cos outer
layout(location = 19) uniform vec3 spotIntensity[MAX_SPOTS];
layout(location = 23) uniform mat4 spotClipFromWorld[MAX_SPOTS];
layout(binding = 1) uniform sampler2DShadow spotShadow[MAX_SPOTS];
// The sun's light texture (crep/scatter/light_texture.h's rule, bilinear, clamp to edge): its colour
// multiplies the sun's irradiance (a stained-glass window's coloured patches on the floor).
layout(location = 27) uniform int sunTextured;
layout(location = 28) uniform mat4 sunTextureClipFromWorld;
layout(binding = 5) uniform sampler2D sunTexture;
layout(location = 0) out vec4 outColor;

float shadowVisibility(vec3 p, float bias) {
  vec4 clip = shadowClipFromWorld * vec4(p, 1.0);
  vec3 ndc = clip.xyz / clip.w;
  vec3 uvz = ndc * 0.5 + 0.5;
  if (any(lessThan(uvz.xy, vec2(0.0))) || any(greaterThan(uvz.xy, vec2(1.0)))) return 1.0;
  vec2 texel = 1.0 / vec2(textureSize(shadowMap, 0));
  float sum = 0.0;
  for (int j = -1; j <= 1; ++j)
    for (int i = -1; i <= 1; ++i) sum += texture(shadowMap, vec3(uvz.xy + vec2(i, j) * texel, uvz.z - bias));
  return sum / 9.0;
}

// Visibility of p in spot i's perspective map (outside it or behind the light: lit).
float spotVisibility(int i, vec3 p) {
  vec4 clip = spotClipFromWorld[i] * vec4(p, 1.0);
  if (clip.w <= 0.0) return 1.0;
  vec3 uvz = clip.xyz / clip.w * 0.5 + 0.5;
  if (any(lessThan(uvz.xy, vec2(0.0))) || any(greaterThan(uvz.xy, vec2(1.0)))) return 1.0;
  vec2 texel = 1.0 / vec2(textureSize(spotShadow[i], 0));
  float sum = 0.0;
  for (int j = -1; j <= 1; ++j)
    for (int k = -1; k <= 1; ++k) sum += texture(spotShadow[i], vec3(uvz.xy + vec2(k, j) * texel, uvz.z - 2e-4));
  return sum / 9.0;
}

// Irradiance of the spot lights at p with normal n (crep::SpotLight: intensity x s(t) / d^2, s = t^2 (3 - 2t)).
vec3 spotIrradiance(vec3 p, vec3 n) {
  vec3 sum = vec3(0.0);
  for (int i = 0; i < spotCount; ++i) {
    vec3 toLight = spotPosition[i] - p;
    float d2 = dot(toLight, toLight);
    vec3 l = toLight * inversesqrt(d2);
    float cosine = dot(n, l);
    if (cosine <= 0.0) continue;
    float t = clamp((dot(-l, spotAxis[i]) - spotCone[i].y) / (spotCone[i].x - spotCone[i].y), 0.0, 1.0);
    float falloff = t * t * (3.0 - 2.0 * t);
    if (falloff <= 0.0) continue;
    sum += spotIntensity[i] * (falloff * cosine / d2) * spotVisibility(i, p + n * 0.05);
  }
  return sum;
}

void main() {
  vec3 n = normalize(worldNormal);
  if (!gl_FrontFacing) n = -n; // two-sided: leaves and open quads (winding is CCW around the normal)
  vec3 toLight = -normalize(lightDirection);
  float cosine = max(dot(n, toLight), 0.0);
  float bias = 0.0015 + 0.003 * (1.0 - cosine);
  float v = cosine > 0.0 ? shadowVisibility(worldPosition + n * 0.02, bias) : 0.0;
  vec3 sunColor = vec3(1.0);
  if (sunTextured != 0) {
    vec4 q = sunTextureClipFromWorld * vec4(worldPosition, 1.0);
    sunColor = q.w > 0.0 ? texture(sunTexture, 0.5 * q.xy / q.w + 0.5).rgb : vec3(0.0);
  }
  vec3 radiance = albedo / 3.14159265358979 * (lightIrradiance * sunColor * cosine * v + spotIrradiance(worldPosition, n)) +
                  albedo * ambient;
  outColor = vec4(radiance, 1.0);
}
