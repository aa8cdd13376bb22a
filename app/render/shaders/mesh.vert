#version 450
// Branches, leaves, lobes and stroke tubes: world-space vertices (metres, +Y up).
layout(location = 0) in vec3 in_position;
layout(location = 1) in vec3 in_normal;
layout(location = 2) in vec2 in_uv;

layout(push_constant) uniform Push {
    mat4 view_proj; // world -> clip
    vec4 color;     // linear RGBA of the material
    vec4 eye;       // camera position
    vec4 params;    // x: material (0 bark, 1 leaf, 2 lobe, 3 stroke, 4 photo)
} pc;

layout(location = 0) out vec3 v_normal;
layout(location = 1) out vec2 v_uv;
layout(location = 2) out vec3 v_world;

void main()
{
    v_normal = in_normal;
    v_uv = in_uv;
    v_world = in_position;
    gl_Position = pc.view_proj * vec4(in_position, 1.0);
}
