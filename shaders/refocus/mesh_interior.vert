// Interior triangles of the grid mesh (every corner surrounded by kept triangles), drawn
// indexed: one invocation per grid vertex, whose id (i + j (W+2)) comes from the index buffer.
// Same pose: the corner projects through the target projection with Z = 1 (w = 1: the map is
// affine); only the depth-test value uses its metric Z.


void main() {
    int row = u_src_size.x + 2;
    ivec2 c = ivec2(gl_VertexID % row, gl_VertexID / row);
    vec2 uv = vec2(vertex_pos(c.x, u_src_size.x), vertex_pos(c.y, u_src_size.y));
    vec4 clip = u_clip_from_target * vec4((uv - u_src_k.zw) / u_src_k.xy, 1.0, 1.0);
    gl_Position = vec4(clip.xy / clip.w, u_clip_z.x + u_clip_z.y / vertex_depth(c), 1.0);
}
