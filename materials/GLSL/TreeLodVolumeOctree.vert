#version 330 core
// The volumetric octree tree (VolumeOctreeData.h; Linz et al. 2006): one billboard a cell, facing
// the viewer (the camera's right and up axes in the model's frame), its corners (+-1, +-1).
// - Level of detail (§3.1, volumeOctreeDrawsCell): a cell of the active level L draws when its
//   parent's centre lies in front of L's distance plane, a cell of level L - 1 when its own centre
//   lies behind it; any other cell collapses off screen.
// - Texture (§2.1): the two input cameras nearest the view (chosen per object on the CPU); each
//   one's slot gives a colour and an alpha codeword (§4.1), a 4x4 block of the atlas; a pruned
//   slot (§3.2) gives weight 0.
// CASTER: the same billboards facing the shadow camera, the two input cameras nearest the light;
//   passes clip z and w and the cell on.
uniform mat4 worldViewProj;
uniform mat4 worldView;
uniform vec4 lodState;   // active level, plane depth (view metres), weight of camera 0, of camera 1
uniform vec4 cameraPair; // input camera 0, input camera 1
uniform vec4 octree;     // cameras, slot texture width, atlas blocks a row, atlas width
uniform sampler2D slots;

in vec4 vertex; // the cell's centre
in vec4 uv0;    // corner x, corner y, level, cell index
in vec4 uv1;    // the parent's centre, half the cell's edge

out vec2 vTexel;             // billboard texels, (0, 0) top-left, (4, 4) bottom-right
flat out vec4 vColourBlocks; // atlas texel origins of camera 0's and camera 1's colour codewords
flat out vec4 vAlphaBlocks;  // ... of their alpha codewords
flat out vec2 vWeights;
#ifdef CASTER
out vec2 vClipZW;
flat out float vCell;
#endif

// The codewords of the slot of `cell` for `camera`: (colour, alpha), -1 when pruned.
ivec2 codewords(int cell, int camera)
{
    int slot = cell * int(octree.x) + camera;
    int width = int(octree.y);
    vec4 bytes = texelFetch(slots, ivec2(slot % width, slot / width), 0) * 255.0 + 0.5;
    int colour = int(bytes.r) + 256 * int(bytes.g);
    int alpha = int(bytes.b) + 256 * int(bytes.a);
    return colour == 65535 ? ivec2(-1) : ivec2(colour, alpha);
}

vec2 blockOrigin(int block)
{
    int perRow = int(octree.z);
    return 4.0 * vec2(float(block % perRow), float(block / perRow));
}

void main()
{
    float level = uv0.z;
    float activeLevel = lodState.x;
    float depth = -(worldView * vec4(vertex.xyz, 1.0)).z;
    float parentDepth = -(worldView * vec4(uv1.xyz, 1.0)).z;
    bool drawn = activeLevel < 0.5 ? level < 0.5
                              : (abs(level - activeLevel) < 0.5 ? parentDepth < lodState.y
                                                           : abs(level + 1.0 - activeLevel) < 0.5 && depth >= lodState.y);
    ivec2 first = codewords(int(uv0.w + 0.5), int(cameraPair.x + 0.5));
    ivec2 second = codewords(int(uv0.w + 0.5), int(cameraPair.y + 0.5));
    vWeights = vec2(first.x >= 0 ? lodState.z : 0.0, second.x >= 0 ? lodState.w : 0.0);
    if (!drawn || vWeights.x + vWeights.y <= 0.0)
    {
        gl_Position = vec4(2.0, 2.0, 2.0, 1.0); // outside the clip volume
        vTexel = vec2(0.0);
        vColourBlocks = vec4(0.0);
        vAlphaBlocks = vec4(0.0);
#ifdef CASTER
        vClipZW = vec2(0.0, 1.0);
        vCell = 0.0;
#endif
        return;
    }
    vColourBlocks = vec4(blockOrigin(max(first.x, 0)), blockOrigin(max(second.x, 0)));
    vAlphaBlocks = vec4(blockOrigin(max(first.y, 0)), blockOrigin(max(second.y, 0)));
    vec3 right = normalize(vec3(worldView[0][0], worldView[1][0], worldView[2][0]));
    vec3 up = normalize(vec3(worldView[0][1], worldView[1][1], worldView[2][1]));
    vec3 position = vertex.xyz + (uv0.x * right + uv0.y * up) * uv1.w;
    vTexel = vec2(uv0.x + 1.0, 1.0 - uv0.y) * 2.0;
    gl_Position = worldViewProj * vec4(position, 1.0);
#ifdef CASTER
    vClipZW = gl_Position.zw;
    vCell = uv0.w;
#endif
}
