// The benchmark's floor: a plain Blinn-Phong sphere, one light, no tone map.
// Prepended with "#version 330 core" and VERTEX_SHADER or FRAGMENT_SHADER by floor.py.
#ifdef VERTEX_SHADER
in vec3 in_position;
uniform mat4 u_view_proj;
out vec3 v_normal;
out vec3 v_world;

void main() {
    v_normal = in_position;  // unit sphere at the origin: the position is the normal
    v_world = in_position;
    gl_Position = u_view_proj * vec4(in_position, 1.0);
}
#endif

#ifdef FRAGMENT_SHADER
in vec3 v_normal;
in vec3 v_world;
uniform vec3 u_eye;
uniform vec3 u_light;
out vec4 frag_color;

void main() {
    vec3 n = normalize(v_normal);
    vec3 l = normalize(u_light - v_world);
    vec3 v = normalize(u_eye - v_world);
    vec3 h = normalize(l + v);
    float diffuse = max(dot(n, l), 0.0);
    float spec = pow(max(dot(n, h), 0.0), 64.0);
    vec3 colour = vec3(0.6, 0.3, 0.2) * diffuse + vec3(0.5) * spec + vec3(0.03);
    frag_color = vec4(pow(clamp(colour, 0.0, 1.0), vec3(1.0 / 2.2)), 1.0);
}
#endif
