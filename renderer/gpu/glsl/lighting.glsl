// lighting.glsl — Lambert + Blinn-Phong with a headlight-relative or fixed light.
// n, l, v are unit vectors: surface normal, direction to the light, direction to the eye.
struct sl_material {
    float ambient, diffuse, specular, shininess;
};

vec3 sl_shade(vec3 base, vec3 n, vec3 l, vec3 v, sl_material m)
{
    if (dot(n, v) < 0.0)
        n = -n; // two-sided: back faces seen from inside are lit as front faces
    float diff = max(dot(n, l), 0.0);
    vec3 h = normalize(l + v);
    float spec = diff > 0.0 ? pow(max(dot(n, h), 0.0), m.shininess) : 0.0;
    return base * (m.ambient + m.diffuse * diff) + vec3(m.specular * spec);
}
