#version 450
// Sky gradient by the elevation of the viewing ray: haze at the horizon, blue at the zenith.
layout(push_constant) uniform Push {
    mat4 inverse_view_proj;
    vec4 color;
    vec4 eye;
    vec4 params;
} pc;

layout(location = 0) in vec3 v_far;
layout(location = 0) out vec4 out_color;

const vec3 kZenith = vec3(0.20, 0.38, 0.72);
const vec3 kHorizon = vec3(0.72, 0.80, 0.88);
const vec3 kBelow = vec3(0.56, 0.58, 0.58);

void main()
{
    const vec3 dir = normalize(v_far - pc.eye.xyz);
    const float up = dir.y;
    vec3 rgb = up >= 0.0 ? mix(kHorizon, kZenith, pow(clamp(up, 0.0, 1.0), 0.6)) : mix(kHorizon, kBelow, clamp(-up * 4.0, 0.0, 1.0));
    out_color = vec4(rgb, 1.0);
}
