// Vertex side of a shadow receiver (SHADOW_RECEIVER; TreeLodShading.glsl reads the result): the
// point in each of the sun's shadow textures' clip space, up to three (PSSM's splits).
// SHADOW_POSITIONS_OUT(s0, s1, s2) goes in main's parameters, the outputs with semantics s0, s1, s2
// (the fragment program's SHADOW_POSITIONS_IN takes the same).
uniform mat4 texViewProj[3]; // param_named_auto texture_viewproj_matrix_array 3

#define SHADOW_POSITIONS_OUT(s0, s1, s2) OUT(vec4 vShadowPos0, s0) OUT(vec4 vShadowPos1, s1) OUT(vec4 vShadowPos2, s2)

void shadowPositions(vec4 world, out vec4 shadowPos0, out vec4 shadowPos1, out vec4 shadowPos2)
{
    shadowPos0 = mul(texViewProj[0], world);
    shadowPos1 = mul(texViewProj[1], world);
    shadowPos2 = mul(texViewProj[2], world);
}
#define passShadowPositions(world) shadowPositions(world, vShadowPos0, vShadowPos1, vShadowPos2)
