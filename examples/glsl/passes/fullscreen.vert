#version 450 core
// One triangle covering the viewport, from gl_VertexID alone: draw 3 vertices with an empty vertex
// array (glDrawArrays(GL_TRIANGLES, 0, 3)). texCoord is 0 at the bottom-left corner of the viewport
// and 1 at the top-right one.
layout(location = 0) out vec2 texCoord;

void main() {
  vec2 p = vec2(float((gl_VertexID & 1) << 2), float((gl_VertexID & 2) << 1)) - 1.0; // (-1,-1) (3,-1) (-1,3)
  texCoord = p * 0.5 + 0.5;
  gl_Position = vec4(p, 0.0, 1.0);
}
