#version 450 core
// Built-in scenes, depth-only pass: the depth is all that is written.
void main() {}
