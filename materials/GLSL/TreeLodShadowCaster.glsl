// What a shadow caster writes, in the mode shadowMode.x names (TreeLodShadowParams, set by the
// tree objects from their scene manager's shadow technique, ShadowSetup.h): for depth shadows
// (integrated texture shadows) the shadow camera's window depth, 0..1, which the receivers compute
// too (TreeLodShading.glsl); for Ogre's colour texture shadows what Ogre's own caster pass writes,
// the shadow colour (modulative) or black (additive).
uniform vec4 shadowMode;   // x: 0 depth, 1 modulative, 2 additive
uniform vec4 shadowColour;

vec4 casterOutput(float depth)
{
    if (shadowMode.x < 0.5)
        return vec4(depth, depth, depth, 1.0);
    return shadowMode.x < 1.5 ? vec4(shadowColour.rgb, 1.0) : vec4(0.0, 0.0, 0.0, 1.0);
}
