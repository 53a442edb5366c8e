// The environment light's parameters as gl/environment_light.py sets them, by name,
// and the Environment lib/environment_light.glsl takes, filled from them. Included,
// in place of the library, by the programs that light by an environment map.
#ifndef ENVIRONMENT_PARAMS_GLSL
#define ENVIRONMENT_PARAMS_GLSL
uniform sampler2D u_env_map;
#include "lib/environment_light.glsl"

uniform float u_env_rotation;
uniform float u_env_intensity;
uniform vec2 u_env_size;
uniform float u_env_max_lod;
uniform int u_env_pass;
uniform float u_env_total;
uniform vec2 u_env_lobe_rotation[3];
uniform vec3 u_env_sh[9];
#ifdef COAT
uniform float u_env_coat_total;
#endif

Environment environment_params() {
    Environment env;
    // Once a fragment, not at each of its lobe samples.
    env.turn = vec2(cos(u_env_rotation), sin(u_env_rotation));
    env.intensity = u_env_intensity;
    env.size = u_env_size;
    env.max_lod = u_env_max_lod;
    env.pass = u_env_pass;
    env.total = u_env_total;
    env.lobe_rotation = u_env_lobe_rotation;
    env.sh = u_env_sh;
#ifdef COAT
    env.coat_total = u_env_coat_total;
#endif
    return env;
}

#endif
