// GPU work lists (crep/scatter/gpu_sample_list.h): the std430 block and its append / read helpers.
// Define CREP_SAMPLE_LIST_BINDING before including to move the block (default storage binding 2).
#ifndef CREP_SAMPLE_LIST_GLSL
#define CREP_SAMPLE_LIST_GLSL

#include "bindings.h"
#ifndef CREP_SAMPLE_LIST_BINDING
#define CREP_SAMPLE_LIST_BINDING CREP_SAMPLE_LIST_DEFAULT_BINDING
#endif
#define CREP_SAMPLE_LIST_GROUP_SIZE 64

// header: x, y, z = glDispatchComputeIndirect groups; w = entries appended.
layout(std430, binding = CREP_SAMPLE_LIST_BINDING) coherent buffer CrepSampleListBlock {
  uvec4 crep_listHeader;
  uint crep_listEntries[];
};

// Appends texel t (x, y < 65536); the thread that opens a new group of 64 entries adds it to groupsX.
void crep_listAppend(uvec2 t) {
  uint i = atomicAdd(crep_listHeader.w, 1u);
  crep_listEntries[i] = t.x | (t.y << 16);
  if (i % uint(CREP_SAMPLE_LIST_GROUP_SIZE) == 0u) atomicAdd(crep_listHeader.x, 1u);
}

uint crep_listCount() { return crep_listHeader.w; }

ivec2 crep_listEntry(uint i) {
  uint e = crep_listEntries[i];
  return ivec2(int(e & 0xFFFFu), int(e >> 16));
}

#endif // CREP_SAMPLE_LIST_GLSL
