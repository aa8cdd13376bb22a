#version 450
// A square ground quad at the trunk base height, centred under the tree.
layout(push_constant) uniform Push {
    mat4 view_proj;
    vec4 area;   // xyz: centre (y = ground height), w: half size in metres
    vec4 eye;
    vec4 params; // x: grid cell size in metres
} pc;

layout(location = 0) out vec3 v_world;

void main()
{
    const vec2 corners[6] = vec2[](vec2(-1, -1), vec2(1, -1), vec2(1, 1), vec2(-1, -1), vec2(1, 1), vec2(-1, 1));
    const vec2 c = corners[gl_VertexIndex];
    v_world = pc.area.xyz + vec3(c.x, 0.0, c.y) * pc.area.w;
    gl_Position = pc.view_proj * vec4(v_world, 1.0);
}
