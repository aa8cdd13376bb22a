#version 450
// The 2D overlay (a Dear ImGui panel): window pixels, origin top-left, y down.
layout(location = 0) in vec2 in_position;
layout(location = 1) in vec2 in_uv;
layout(location = 2) in vec4 in_color; // R8G8B8A8_UNORM: sRGB-encoded colour, linear alpha

layout(push_constant) uniform Push {
    vec2 scale;     // 2 / frame size
    vec2 translate; // -1, -1
} pc;

layout(location = 0) out vec4 v_color;
layout(location = 1) out vec2 v_uv;

void main()
{
    v_color = in_color;
    v_uv = in_uv;
    gl_Position = vec4(in_position * pc.scale + pc.translate, 0.0, 1.0);
}
