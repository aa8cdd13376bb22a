#version 450
// Leaves drawn instanced (app/render/scene_drawer.cpp, docs/rendering.md): one shared quad and one
// instance per leaf. Binding 0 (per vertex) holds the uvs of the quad's four corners, shared
// by every leaf of the mesh; binding 1 (per instance) holds three corners of the leaf and its
// normal. Corner k is vertex k of the leaf's four in the mesh (growth/leaves.cpp's order):
// 0, 1 and 3 are given as they were, 2 is 1 + (3 − 0) (the quad is a parallelogram; the
// renderer checked that it is, to rounding). The outputs are mesh.vert's, so mesh.frag shades
// an instanced leaf exactly as it shades the same leaf drawn as a mesh.
layout(location = 0) in vec2 in_uv;
layout(location = 1) in vec3 in_corner0;
layout(location = 2) in vec3 in_corner1;
layout(location = 3) in vec3 in_corner3;
layout(location = 4) in vec3 in_normal;

layout(push_constant) uniform Push {
    mat4 view_proj; // world -> clip
    vec4 color;     // linear RGBA of the material
    vec4 eye;       // camera position
    vec4 params;    // x: material (1: leaf)
} pc;

layout(location = 0) out vec3 v_normal;
layout(location = 1) out vec2 v_uv;
layout(location = 2) out vec3 v_world;

void main()
{
    // The shared quad's indices are 0..3 and the draw's vertex offset is 0.
    const int corner = gl_VertexIndex;
    vec3 p;
    if (corner == 0)
        p = in_corner0;
    else if (corner == 1)
        p = in_corner1;
    else if (corner == 3)
        p = in_corner3;
    else
        p = in_corner1 + (in_corner3 - in_corner0);
    v_normal = in_normal;
    v_uv = in_uv;
    v_world = p;
    gl_Position = pc.view_proj * vec4(p, 1.0);
}
