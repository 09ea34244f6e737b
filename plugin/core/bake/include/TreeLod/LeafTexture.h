// LeafTexture: procedurally drawn leaf and bark textures for the generated trees.
//
// Leaf: RGBA8, straight alpha, rows top to bottom (glTF/PNG convention), sRGB colour.
// The leaf stands upright in the image: petiole at the bottom edge (v = 1), tip at the top
// (v = 0), centred in u. Alpha is the leaf silhouette with an anti-aliased edge (4x4
// supersampled coverage, 2x2 above 1024 texels); colour is bled into the transparent
// texels (16 texels out, then the mean leaf colour) so that mipmaps and bilinear filtering
// don't darken the edge. Shapes: oak lobed, birch ovate serrated,
// conifer a needle spray on a twig, shrub small ovate; colour has a base-to-tip gradient,
// a midrib, side veins and faint noise.
//
// Bark: RGBA8 (alpha 255), tiles in both directions (u around the stem, v along it).
// Oak: dark brown vertical furrows; conifer: red-brown plates; birch: white with dark
// horizontal lenticels; shrub: grey-brown.
#pragma once

#include "TreeLod/TreeGenerator.h"
#include "TreeLod/TreeModel.h"

namespace TreeLod
{
    /// Width / length of the leaf quad the texture is drawn for (the generator builds its
    /// quads with this aspect so the drawn shape is not stretched).
    float leafAspect(TreePreset preset);

    /// Square leaf texture of `size` x `size` texels (size >= 4). Deterministic.
    TextureImage drawLeafTexture(TreePreset preset, int size);

    /// Bark texture, `width` x `height` texels (each >= 4), tiling. Deterministic.
    TextureImage drawBarkTexture(TreePreset preset, int width, int height);

    /// The mean colour of the opaque leaf texels, linear RGB (what a leaf looks like
    /// from far away); used for the leaf material's back colour.
    glm::vec3 leafMeanColour(const TextureImage& leafTexture);
}
