// Vulkan layer shared by every pass compiled to SPIR-V (build.rs; glslang defines VULKAN).
// gl_VertexIndex is gl_VertexID plus the draw's firstVertex / vertexOffset, which the Vulkan
// backend always leaves at 0, so the GL sources keep their name for it.
#define gl_VertexID gl_VertexIndex
// The std140 parameter block (binding 0) is a read-only storage buffer here and a uniform block
// under GL (the GL loader defines PARAM_BLOCK as `uniform`): lavapipe (Mesa 22) compiles a new
// shader at every pipeline bind whose uniform-block values steer loops or branches (it inlines
// them) and never frees it, about 1 MB a draw, so a sequence grew with every frame. Storage
// buffers are never inlined.
#define PARAM_BLOCK readonly buffer
