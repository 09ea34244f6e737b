#version 330 core
// The volumetric octree tree's billboard (TreeLodVolumeOctree.vert): the two input cameras'
// codewords sampled bilinearly inside their 4x4 blocks, premultiplied and weighted, for the over
// operator (scene_blend one one_minus_src_alpha). Colour is sRGB as stored; the framebuffer holds
// sRGB, so blending happens there as in renderVolumeOctree (VolumeOctreeBaker.h).
uniform sampler2D codebook;
uniform vec4 octree;      // cameras, slot texture width, atlas blocks a row, atlas width
uniform float atlasHeight;

in vec2 vTexel;
flat in vec4 vColourBlocks;
flat in vec4 vAlphaBlocks;
flat in vec2 vWeights;

out vec4 fragColour;

vec4 premultiplied(vec2 colourBlock, vec2 alphaBlock, vec2 texel)
{
    vec2 size = vec2(octree.w, atlasHeight);
    vec3 colour = texture(codebook, (colourBlock + texel) / size).rgb;
    float alpha = texture(codebook, (alphaBlock + texel) / size).a;
    return vec4(colour * alpha, alpha);
}

void main()
{
    vec2 texel = clamp(vTexel, vec2(0.5), vec2(3.5));
    vec4 colour = vWeights.x * premultiplied(vColourBlocks.xy, vAlphaBlocks.xy, texel) +
                  vWeights.y * premultiplied(vColourBlocks.zw, vAlphaBlocks.zw, texel);
    if (colour.a < 0.5 / 255.0)
        discard;
    fragColour = colour;
}
