#!/usr/bin/env node
// Generate a tree with ez-tree (@dgreenheck/ez-tree, MIT, Daniel Greenheck) and write it as
// binary glTF with three's GLTFExporter, under node.
//
//   node tools/ez-tree/generate.mjs --preset "Pine Medium" --seed 13977 -o out.glb
//   node tools/ez-tree/generate.mjs --list
//
// The export is what ez-tree's own web app does for "Export GLB" (GLTFExporter.parse of the
// Tree with { binary: true }), except that:
// - textures wider than --max-texture-size (default 512) are downscaled (GLTFExporter's
//   maxTextureSize option; an alpha-weighted box filter in browser-polyfills.mjs);
// - the metallic-roughness texture's UV set is written as glTF's "texCoord", not three r167's
//   "channel", and each PNG's buffer view ends at the PNG's IEND (no padding bytes inside);
// - the glTF asset records the preset, the seed and the copyright.
// The materials stay ez-tree's MeshPhongMaterials, which GLTFExporter writes with metallic and
// roughness factors of 0.5 and the bark's roughness map merged into a metallic-roughness texture.
// The same preset, seed and options give the same bytes: ez-tree's RNG is seeded, the image
// codecs are pure JavaScript, and the polyfills complete asynchronous work in a fixed order.
//
// Run `npm ci` in tools/ez-tree first (package-lock.json pins every package).
import { readFileSync, writeFileSync, mkdirSync } from 'node:fs';
import { dirname, resolve } from 'node:path';
import { parseArgs } from 'node:util';
import { installBrowserPolyfills, whenImagesSettled } from './browser-polyfills.mjs';

const usage = `usage: node generate.mjs --preset NAME [--seed N] [--max-texture-size PX] -o OUT.glb
       node generate.mjs --list
  --preset NAME           an ez-tree preset (see --list), e.g. "Pine Medium"
  --seed N                integer seed (default: the preset's own seed)
  --max-texture-size PX   downscale larger textures to at most PX per side (default 512;
                          0 keeps ez-tree's 1024 px textures)
  -o, --output OUT.glb    the .glb to write
  --list                  print the preset names, one a line`;

function die(message) {
  console.error(`generate.mjs: ${message}\n${usage}`);
  process.exit(2);
}

let args;
try {
  args = parseArgs({
    options: {
      preset: { type: 'string' },
      seed: { type: 'string' },
      'max-texture-size': { type: 'string', default: '512' },
      output: { type: 'string', short: 'o' },
      list: { type: 'boolean', default: false },
      help: { type: 'boolean', short: 'h', default: false },
    },
    strict: true,
  }).values;
} catch (e) {
  die(e.message);
}
if (args.help) {
  console.log(usage);
  process.exit(0);
}

// ez-tree loads all its textures when it is imported, through THREE.TextureLoader, so the
// browser stand-ins must exist before the import.
installBrowserPolyfills();
const THREE = await import('three');
const { GLTFExporter } = await import('three/examples/jsm/exporters/GLTFExporter.js');
const { Tree, TreePreset } = await import('@dgreenheck/ez-tree');

if (args.list) {
  for (const name of Object.keys(TreePreset)) console.log(name);
  process.exit(0);
}

if (!args.preset) die('--preset is required');
if (!Object.hasOwn(TreePreset, args.preset))
  die(`unknown preset '${args.preset}'; one of: ${Object.keys(TreePreset).join(', ')}`);
if (!args.output) die('-o OUT.glb is required');
let seed = TreePreset[args.preset].seed;
if (args.seed !== undefined) {
  if (!/^-?\d+$/.test(args.seed)) die(`--seed must be an integer, got '${args.seed}'`);
  seed = Number(args.seed);
}
if (!/^\d+$/.test(args['max-texture-size'])) die('--max-texture-size must be a whole number of pixels');
const maxTextureSize = Number(args['max-texture-size']) || Infinity;

const tree = new Tree();
tree.loadPreset(args.preset); // copies the preset's options and generates
tree.options.seed = seed;
tree.generate();
await whenImagesSettled(); // the textures' 'load' events have set texture.image

for (const mesh of [tree.branchesMesh, tree.leavesMesh]) {
  for (const map of ['map', 'normalMap', 'aoMap', 'roughnessMap']) {
    const texture = mesh.material[map];
    if (texture && !texture.image) throw new Error(`${mesh.material.name}.${map} did not load`);
  }
}

const ezTreePackage = new URL('./node_modules/@dgreenheck/ez-tree/package.json', import.meta.url);
const versions = {
  ezTree: JSON.parse(readFileSync(ezTreePackage, 'utf8')).version,
  three: THREE.REVISION,
};

const leafQuads = tree.leaves.indices.length / 6;
const box = new THREE.Box3().setFromObject(tree);
const size = box.getSize(new THREE.Vector3());

const exporter = new GLTFExporter();
exporter.register((writer) => ({
  // three r167 writes the metallic-roughness texture's UV set as "channel" (a three.js name)
  // instead of glTF's "texCoord"; write the glTF name.
  writeMaterial(material, materialDef) {
    const info = materialDef.pbrMetallicRoughness?.metallicRoughnessTexture;
    if (info && 'channel' in info) {
      info.texCoord = info.channel;
      delete info.channel;
    }
  },
  afterParse() {
    writer.json.asset.copyright =
      'ez-tree (c) 2024 Daniel Greenheck, MIT licence; textures: see media/third-party/LICENSES.md';
    writer.json.asset.extras = {
      source: `@dgreenheck/ez-tree ${versions.ezTree} with three r${versions.three}`,
      preset: args.preset,
      seed,
      maxTextureSize: Number.isFinite(maxTextureSize) ? maxTextureSize : null,
    };
  },
}));

// GLTFExporter warns that MeshPhongMaterial is not MeshStandardMaterial and that it merged the
// roughness map into a metallic-roughness texture; both are expected for ez-tree's materials.
const warn = console.warn;
console.warn = (...m) => {
  const text = m.join(' ');
  if (/Use MeshStandardMaterial|Merged metalnessMap and roughnessMap/.test(text)) return;
  warn(...m);
};
const glb = await exporter.parseAsync(tree, { binary: true, maxTextureSize });
console.warn = warn;

/**
 * GLTFExporter gives each image's buffer view the image's length padded to 4 bytes, so a PNG
 * ends in up to 3 zero bytes after its IEND chunk, which strict PNG readers refuse. Set each
 * PNG buffer view's byteLength to the PNG's own length (the padding stays in the buffer,
 * between views) and rewrite the JSON chunk; the BIN chunk is unchanged.
 */
function trimImageBufferViews(glbBytes) {
  const glbData = Buffer.from(glbBytes);
  const jsonLength = glbData.readUInt32LE(12);
  const json = JSON.parse(glbData.subarray(20, 20 + jsonLength).toString('utf8'));
  const binStart = 20 + jsonLength + 8;
  for (const image of json.images ?? []) {
    if (image.mimeType !== 'image/png' || image.bufferView === undefined) continue;
    const view = json.bufferViews[image.bufferView];
    const png = glbData.subarray(binStart + (view.byteOffset ?? 0), binStart + (view.byteOffset ?? 0) + view.byteLength);
    let pos = 8;
    for (;;) {
      if (pos + 12 > png.length) throw new Error('exported PNG has no IEND chunk');
      const chunkLength = png.readUInt32BE(pos);
      const type = png.toString('latin1', pos + 4, pos + 8);
      pos += 12 + chunkLength;
      if (type === 'IEND') break;
    }
    view.byteLength = pos;
  }
  let text = Buffer.from(JSON.stringify(json), 'utf8');
  text = Buffer.concat([text, Buffer.alloc((4 - (text.length % 4)) % 4, 0x20)]);
  const bin = glbData.subarray(20 + jsonLength);
  const header = Buffer.alloc(20);
  header.writeUInt32LE(0x46546c67, 0); // 'glTF'
  header.writeUInt32LE(2, 4);
  header.writeUInt32LE(20 + text.length + bin.length, 8);
  header.writeUInt32LE(text.length, 12);
  header.writeUInt32LE(0x4e4f534a, 16); // 'JSON'
  return Buffer.concat([header, text, bin]);
}

const bytes = trimImageBufferViews(glb);
const out = resolve(args.output);
mkdirSync(dirname(out), { recursive: true });
writeFileSync(out, bytes);
console.log(
  `${out}: ${bytes.length} bytes; preset '${args.preset}', seed ${seed}; ` +
    `${leafQuads} leaf quads (${tree.options.leaves.billboard} billboards), ` +
    `size ${size.x.toFixed(2)} x ${size.y.toFixed(2)} x ${size.z.toFixed(2)} (x, y up, z)`,
);
