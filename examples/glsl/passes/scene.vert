#version 450 core
// Built-in scenes: transforms positions by clipFromWorld; passes world position and normal on.
layout(location = 0) in vec3 inPosition;
layout(location = 1) in vec3 inNormal;
layout(location = 0) uniform mat4 clipFromWorld;
layout(location = 0) out vec3 worldPosition;
layout(location = 1) out vec3 worldNormal;
void main() {
  worldPosition = inPosition;
  worldNormal = inNormal;
  gl_Position = clipFromWorld * vec4(inPosition, 1.0);
}
