#version 450
// The overlay's colour is given in sRGB (as the panel means it) and interpolated so; the
// target is an sRGB format, which encodes what is written: decode to linear here so the
// colour comes out as given. The font atlas is an sRGB texture (sampled as linear).
layout(set = 0, binding = 0) uniform sampler2D font;

layout(location = 0) in vec4 v_color;
layout(location = 1) in vec2 v_uv;

layout(location = 0) out vec4 out_color;

vec3 srgb_to_linear(vec3 c)
{
    return mix(c / 12.92, pow((c + 0.055) / 1.055, vec3(2.4)), greaterThan(c, vec3(0.04045)));
}

void main()
{
    out_color = vec4(srgb_to_linear(v_color.rgb), v_color.a) * texture(font, v_uv);
}
