#version 450 core
// Built-in scenes, lit pass: Lambert with a standard shadow map (3x3 PCF) plus ambient.
layout(location = 0) in vec3 worldPosition;
layout(location = 1) in vec3 worldNormal;
layout(location = 1) uniform mat4 shadowClipFromWorld;
layout(location = 2) uniform vec3 lightDirection; // direction the light travels
layout(location = 3) uniform vec3 lightIrradiance;
layout(location = 4) uniform vec3 ambient;
layout(location = 5) uniform vec3 albedo;
layout(binding = 0) uniform sampler2DShadow shadowMap;
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

void main() {
  vec3 n = normalize(worldNormal);
  if (!gl_FrontFacing) n = -n; // two-sided: leaves and open quads (winding is CCW around the normal)
  vec3 toLight = -normalize(lightDirection);
  float cosine = max(dot(n, toLight), 0.0);
  float bias = 0.0015 + 0.003 * (1.0 - cosine);
  float v = cosine > 0.0 ? shadowVisibility(worldPosition + n * 0.02, bias) : 0.0;
  vec3 radiance = albedo / 3.14159265358979 * (lightIrradiance * cosine * v) + albedo * ambient;
  outColor = vec4(radiance, 1.0);
}
