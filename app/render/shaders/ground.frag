#version 450
// Ground grid: thin lines every cell, stronger every tenth line, antialiased by the screen
// footprint, fading into the horizon haze with distance.
layout(push_constant) uniform Push {
    mat4 view_proj;
    vec4 area;
    vec4 eye;
    vec4 params;
} pc;

layout(location = 0) in vec3 v_world;
layout(location = 0) out vec4 out_color;

const vec3 kGround = vec3(0.40, 0.38, 0.33);
const vec3 kLine = vec3(0.24, 0.23, 0.21);
const vec3 kHorizon = vec3(0.72, 0.80, 0.88);

float grid_line(vec2 p, float cell)
{
    const vec2 q = p / cell;
    const vec2 width = max(fwidth(q), vec2(1e-6));
    const vec2 d = abs(fract(q - 0.5) - 0.5) / width;
    return 1.0 - min(min(d.x, d.y), 1.0);
}

void main()
{
    const float cell = pc.params.x;
    const vec2 p = v_world.xz - pc.area.xz;
    const float line = max(0.6 * grid_line(p, cell), grid_line(p, cell * 10.0));
    vec3 rgb = mix(kGround, kLine, line);
    const float r = length(p) / pc.area.w;
    rgb = mix(rgb, kHorizon, smoothstep(0.35, 1.0, r));
    out_color = vec4(rgb, 1.0);
}
