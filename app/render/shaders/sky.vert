#version 450
// A full-screen triangle; each corner carries the world point it sees on the far plane.
layout(push_constant) uniform Push {
    mat4 inverse_view_proj; // clip -> world
    vec4 color;
    vec4 eye;
    vec4 params;
} pc;

layout(location = 0) out vec3 v_far;

void main()
{
    const vec2 ndc = vec2(float((gl_VertexIndex << 1) & 2), float(gl_VertexIndex & 2)) * 2.0 - 1.0;
    const vec4 far = pc.inverse_view_proj * vec4(ndc, 1.0, 1.0);
    v_far = far.xyz / far.w;
    gl_Position = vec4(ndc, 1.0, 1.0);
}
