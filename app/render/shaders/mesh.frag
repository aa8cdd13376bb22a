#version 450
// Diffuse sun + hemisphere ambient. Leaves are alpha-tested and two-sided (the normal is
// flipped on back faces, and light through a leaf lights its back a little); lobes are
// translucent; strokes are nearly unlit so they read as marks on the sketch. Photos are unlit:
// the photo texture (sRGB, sampled as linear) times the colour, opaque, both sides alike.
layout(push_constant) uniform Push {
    mat4 view_proj;
    vec4 color;
    vec4 eye;
    vec4 params;
} pc;

layout(set = 0, binding = 0) uniform sampler2D leaf_texture;
layout(set = 0, binding = 1) uniform sampler2D photo_texture;

layout(location = 0) in vec3 v_normal;
layout(location = 1) in vec2 v_uv;
layout(location = 2) in vec3 v_world;

layout(location = 0) out vec4 out_color;

const vec3 kSunDirection = vec3(0.42, 0.78, 0.46); // towards the sun (normalised below)
const vec3 kSunColor = vec3(1.00, 0.95, 0.86);
const vec3 kSkyAmbient = vec3(0.52, 0.62, 0.78);
const vec3 kGroundAmbient = vec3(0.28, 0.25, 0.21);

void main()
{
    const int material = int(pc.params.x + 0.5);
    if (material == 4) {
        out_color = vec4(pc.color.rgb * texture(photo_texture, v_uv).rgb, 1.0);
        return;
    }
    vec3 n = normalize(v_normal);
    if (!gl_FrontFacing) n = -n;
    vec4 base = pc.color;
    if (material == 1) {
        const vec4 texel = texture(leaf_texture, v_uv);
        if (texel.a < 0.5) discard;
        base.rgb *= texel.rgb;
    }
    const vec3 l = normalize(kSunDirection);
    const float facing = dot(n, l);
    float diffuse = max(facing, 0.0);
    if (material == 1) diffuse += 0.35 * max(-facing, 0.0); // light through the leaf
    const vec3 ambient = mix(kGroundAmbient, kSkyAmbient, 0.5 + 0.5 * n.y);
    vec3 rgb = base.rgb * (0.55 * ambient + 0.85 * kSunColor * diffuse);
    float alpha = 1.0;
    if (material == 2) {
        // Lobes: a soft shell, stronger towards the silhouette so the envelope reads.
        const vec3 v = normalize(pc.eye.xyz - v_world);
        const float rim = 1.0 - abs(dot(n, v));
        rgb = base.rgb * (0.65 + 0.35 * diffuse);
        alpha = clamp(base.a * (0.7 + 1.3 * rim * rim), 0.0, 0.85);
    } else if (material == 3) {
        rgb = base.rgb * (0.75 + 0.25 * diffuse);
    }
    out_color = vec4(rgb, alpha);
}
