// Minimal browser stand-ins so that ez-tree and three's GLTFExporter run under node.
//
// Only what these two libraries call is provided, and anything else throws rather than
// pretending to work:
// - document.createElementNS('…', 'img') / document.createElement('canvas'): three's
//   ImageLoader (ez-tree loads its textures with THREE.TextureLoader at import time, from
//   data: URIs that its build inlines) and GLTFExporter (which draws every texture onto a
//   canvas and encodes it with canvas.toBlob).
// - HTMLImageElement: decodes data:image/png and data:image/jpeg URIs with pngjs and jpeg-js
//   (pure JavaScript, so the pixels are the same on every machine). Width and height are read
//   from the header when src is set; the pixels are decoded on first use (ez-tree loads all
//   twenty of its textures, a tree uses a few).
// - HTMLCanvasElement with a 2D context holding straight (non-premultiplied) RGBA8 pixels:
//   fillRect with a '#rrggbb' fillStyle, drawImage over the whole canvas (scaled with an
//   alpha-weighted box filter, optionally flipped vertically by translate(0, h) + scale(1, -1),
//   the only transform GLTFExporter sets), getImageData/putImageData of the whole canvas, and
//   toBlob for image/png (encoded here with pako's deflate: byte-identical output everywhere)
//   and image/jpeg (jpeg-js, quality 92 like a browser's default).
// - ImageData, and FileReader.readAsArrayBuffer / readAsDataURL over node's own Blob. Reads
//   complete strictly in the order they were started, so the order of GLTFExporter's buffer
//   views (and therefore the output bytes) never depends on timing.
import { Buffer } from 'node:buffer';
import jpeg from 'jpeg-js';
import pako from 'pako';
import pngjs from 'pngjs';

const { PNG } = pngjs;

// ---- image decoding ----------------------------------------------------------------------

function parseDataUri(uri) {
  const m = /^data:([^;,]+)(;base64)?,(.*)$/s.exec(uri);
  if (!m) throw new Error(`only data: URIs can be loaded under node, got '${uri.slice(0, 40)}…'`);
  const bytes = m[2] ? Buffer.from(m[3], 'base64') : Buffer.from(decodeURIComponent(m[3]), 'latin1');
  return { mimeType: m[1], bytes };
}

function sniff(bytes) {
  if (bytes.length > 24 && bytes.readUInt32BE(0) === 0x89504e47) return 'image/png';
  if (bytes.length > 4 && bytes[0] === 0xff && bytes[1] === 0xd8) return 'image/jpeg';
  return 'unknown';
}

/** Width and height from a PNG IHDR or a JPEG SOFn marker, without decoding. */
function imageSize(bytes, kind) {
  if (kind === 'image/png') return { width: bytes.readUInt32BE(16), height: bytes.readUInt32BE(20) };
  let pos = 2;
  while (pos + 9 < bytes.length) {
    if (bytes[pos] !== 0xff) throw new Error('corrupt JPEG: no marker at byte ' + pos);
    const marker = bytes[pos + 1];
    if (marker === 0xff) { pos += 1; continue; }
    const length = bytes.readUInt16BE(pos + 2);
    const isSof = marker >= 0xc0 && marker <= 0xcf && marker !== 0xc4 && marker !== 0xc8 && marker !== 0xcc;
    if (isSof) return { width: bytes.readUInt16BE(pos + 7), height: bytes.readUInt16BE(pos + 5) };
    pos += 2 + length;
  }
  throw new Error('corrupt JPEG: no SOF marker');
}

function decodePixels(bytes, kind) {
  if (kind === 'image/png') {
    // pngjs expands palette + tRNS, grey and 16-bit images to RGBA8.
    const png = PNG.sync.read(bytes);
    return new Uint8ClampedArray(png.data.buffer, png.data.byteOffset, png.data.length);
  }
  const img = jpeg.decode(bytes, { useTArray: true, formatAsRGBA: true });
  return new Uint8ClampedArray(img.data.buffer, img.data.byteOffset, img.data.length);
}

// ---- image encoding ----------------------------------------------------------------------

const CRC_TABLE = (() => {
  const t = new Uint32Array(256);
  for (let n = 0; n < 256; n++) {
    let c = n;
    for (let k = 0; k < 8; k++) c = c & 1 ? 0xedb88320 ^ (c >>> 1) : c >>> 1;
    t[n] = c >>> 0;
  }
  return t;
})();

function crc32(buf) {
  let c = 0xffffffff;
  for (let i = 0; i < buf.length; i++) c = CRC_TABLE[(c ^ buf[i]) & 0xff] ^ (c >>> 8);
  return (c ^ 0xffffffff) >>> 0;
}

function pngChunk(type, data) {
  const out = Buffer.alloc(12 + data.length);
  out.writeUInt32BE(data.length, 0);
  out.write(type, 4, 'latin1');
  Buffer.from(data.buffer, data.byteOffset, data.length).copy(out, 8);
  out.writeUInt32BE(crc32(out.subarray(4, 8 + data.length)), 8 + data.length);
  return out;
}

/**
 * PNG, 8-bit RGBA, or RGB when every pixel is opaque. Each row takes the filter with the
 * smallest sum of absolute differences (libpng's heuristic); pako deflates at level 9.
 */
function encodePng(rgba, width, height) {
  let opaque = true;
  for (let i = 3; i < rgba.length; i += 4) if (rgba[i] !== 255) { opaque = false; break; }
  const bpp = opaque ? 3 : 4;
  const stride = width * bpp;
  const raw = new Uint8Array(stride * height);
  for (let p = 0, o = 0; p < rgba.length; p += 4) {
    raw[o++] = rgba[p]; raw[o++] = rgba[p + 1]; raw[o++] = rgba[p + 2];
    if (!opaque) raw[o++] = rgba[p + 3];
  }
  const filtered = new Uint8Array((stride + 1) * height);
  const candidate = new Uint8Array(stride);
  for (let y = 0; y < height; y++) {
    const row = raw.subarray(y * stride, (y + 1) * stride);
    const prev = y > 0 ? raw.subarray((y - 1) * stride, y * stride) : null;
    let bestType = 0, bestScore = Infinity, best = null;
    for (let type = 0; type < 5; type++) {
      let score = 0;
      for (let x = 0; x < stride; x++) {
        const a = x >= bpp ? row[x - bpp] : 0;
        const b = prev ? prev[x] : 0;
        const c = prev && x >= bpp ? prev[x - bpp] : 0;
        let pred = 0;
        if (type === 1) pred = a;
        else if (type === 2) pred = b;
        else if (type === 3) pred = (a + b) >> 1;
        else if (type === 4) {
          const p = a + b - c, pa = Math.abs(p - a), pb = Math.abs(p - b), pc = Math.abs(p - c);
          pred = pa <= pb && pa <= pc ? a : pb <= pc ? b : c;
        }
        const v = (row[x] - pred) & 0xff;
        candidate[x] = v;
        score += v < 128 ? v : 256 - v;
      }
      if (score < bestScore) { bestScore = score; bestType = type; best = candidate.slice(); }
    }
    filtered[y * (stride + 1)] = bestType;
    filtered.set(best, y * (stride + 1) + 1);
  }
  const ihdr = Buffer.alloc(13);
  ihdr.writeUInt32BE(width, 0);
  ihdr.writeUInt32BE(height, 4);
  ihdr[8] = 8;                 // bit depth
  ihdr[9] = opaque ? 2 : 6;    // colour type: RGB or RGBA
  ihdr[10] = 0; ihdr[11] = 0; ihdr[12] = 0;
  const idat = pako.deflate(filtered, { level: 9 });
  return Buffer.concat([
    Buffer.from([0x89, 0x50, 0x4e, 0x47, 0x0d, 0x0a, 0x1a, 0x0a]),
    pngChunk('IHDR', ihdr),
    pngChunk('IDAT', idat),
    pngChunk('IEND', new Uint8Array(0)),
  ]);
}

function encodeJpeg(rgba, width, height, quality) {
  return jpeg.encode({ data: Buffer.from(rgba.buffer, rgba.byteOffset, rgba.length), width, height }, quality).data;
}

// ---- pixels ------------------------------------------------------------------------------

/**
 * Resample straight RGBA8 (sw x sh) to (dw x dh) with a box filter that weights colour by
 * alpha, as a browser canvas does (it stores premultiplied colour). Where every source pixel
 * is transparent the colour is their plain average rather than black. `flipY` mirrors rows.
 */
function resample(src, sw, sh, dw, dh, flipY) {
  const out = new Uint8ClampedArray(dw * dh * 4);
  if (sw === dw && sh === dh) {
    for (let y = 0; y < dh; y++) {
      const sy = flipY ? sh - 1 - y : y;
      out.set(src.subarray(sy * sw * 4, (sy + 1) * sw * 4), y * dw * 4);
    }
    return out;
  }
  // Per axis: for each destination index the covered source indices and their weights.
  const spans = (s, d) => {
    const list = [];
    const scale = s / d;
    for (let i = 0; i < d; i++) {
      const lo = i * scale, hi = (i + 1) * scale;
      const items = [];
      for (let k = Math.floor(lo); k < Math.min(s, Math.ceil(hi)); k++) {
        const w = Math.min(hi, k + 1) - Math.max(lo, k);
        if (w > 0) items.push([k, w]);
      }
      list.push(items);
    }
    return list;
  };
  const xs = spans(sw, dw), ys = spans(sh, dh);
  // Horizontal pass into float planes: alpha-weighted colour, alpha, plain colour.
  const tmp = new Float64Array(dw * sh * 7);
  for (let y = 0; y < sh; y++) {
    for (let x = 0; x < dw; x++) {
      let r = 0, g = 0, b = 0, a = 0, pr = 0, pg = 0, pb = 0, wsum = 0;
      for (const [k, w] of xs[x]) {
        const p = (y * sw + k) * 4;
        const al = src[p + 3] / 255;
        r += w * src[p] * al; g += w * src[p + 1] * al; b += w * src[p + 2] * al; a += w * al;
        pr += w * src[p]; pg += w * src[p + 1]; pb += w * src[p + 2]; wsum += w;
      }
      const t = (y * dw + x) * 7;
      tmp[t] = r / wsum; tmp[t + 1] = g / wsum; tmp[t + 2] = b / wsum; tmp[t + 3] = a / wsum;
      tmp[t + 4] = pr / wsum; tmp[t + 5] = pg / wsum; tmp[t + 6] = pb / wsum;
    }
  }
  for (let y = 0; y < dh; y++) {
    const oy = flipY ? dh - 1 - y : y;
    for (let x = 0; x < dw; x++) {
      const acc = new Float64Array(7);
      let wsum = 0;
      for (const [k, w] of ys[y]) {
        const t = (k * dw + x) * 7;
        for (let c = 0; c < 7; c++) acc[c] += w * tmp[t + c];
        wsum += w;
      }
      for (let c = 0; c < 7; c++) acc[c] /= wsum;
      const o = (oy * dw + x) * 4;
      const a = acc[3];
      const alpha = Math.round(a * 255);
      if (alpha > 0) {
        out[o] = Math.round(acc[0] / a); out[o + 1] = Math.round(acc[1] / a); out[o + 2] = Math.round(acc[2] / a);
      } else {
        out[o] = Math.round(acc[4]); out[o + 1] = Math.round(acc[5]); out[o + 2] = Math.round(acc[6]);
      }
      out[o + 3] = alpha;
    }
  }
  return out;
}

// ---- DOM classes ---------------------------------------------------------------------------

class MiniEventTarget {
  #listeners = new Map();
  addEventListener(type, fn) {
    if (!this.#listeners.has(type)) this.#listeners.set(type, []);
    this.#listeners.get(type).push(fn);
  }
  removeEventListener(type, fn) {
    const list = this.#listeners.get(type);
    if (list) this.#listeners.set(type, list.filter((f) => f !== fn));
  }
  dispatchEvent(event) {
    for (const fn of [...(this.#listeners.get(event.type) || [])]) fn.call(this, event);
    const handler = this['on' + event.type];
    if (typeof handler === 'function') handler.call(this, event);
  }
}

const pendingLoads = new Set();

/** Resolves once every image whose src was set has fired 'load' or 'error'. */
export function whenImagesSettled() {
  return Promise.all([...pendingLoads]);
}

export class HTMLImageElement extends MiniEventTarget {
  width = 0;
  height = 0;
  naturalWidth = 0;
  naturalHeight = 0;
  complete = false;
  crossOrigin = null;
  #src = '';
  #bytes = null;
  #kind = null;
  #pixels = null;

  get src() { return this.#src; }
  set src(uri) {
    this.#src = uri;
    const done = new Promise((resolve) => {
      setImmediate(() => {
        try {
          const { bytes } = parseDataUri(uri);
          const kind = sniff(bytes);
          if (kind === 'unknown') throw new Error('image is neither PNG nor JPEG');
          const { width, height } = imageSize(bytes, kind);
          this.#bytes = bytes;
          this.#kind = kind;
          this.width = this.naturalWidth = width;
          this.height = this.naturalHeight = height;
          this.complete = true;
          this.dispatchEvent({ type: 'load', target: this });
        } catch (error) {
          this.dispatchEvent({ type: 'error', target: this, error });
        }
        pendingLoads.delete(done);
        resolve();
      });
    });
    pendingLoads.add(done);
  }

  /** The encoded bytes and their type, as loaded. */
  get encoded() { return { bytes: this.#bytes, mimeType: this.#kind }; }

  /** Straight RGBA8, decoded on first use. */
  get pixels() {
    if (!this.#pixels) {
      if (!this.#bytes) throw new Error('image used before it loaded');
      this.#pixels = decodePixels(this.#bytes, this.#kind);
    }
    return this.#pixels;
  }
}

export class ImageData {
  constructor(data, width, height) {
    if (typeof data === 'number') { height = width; width = data; data = new Uint8ClampedArray(width * height * 4); }
    if (data.length !== width * height * 4) throw new Error('ImageData: data length does not match the size');
    this.data = data;
    this.width = width;
    this.height = height;
  }
}

class CanvasRenderingContext2D {
  #canvas;
  #flipY = false;
  #dirtyTransform = false;
  fillStyle = '#000000';

  constructor(canvas) { this.#canvas = canvas; }

  get canvas() { return this.#canvas; }

  translate(x, y) {
    if (x !== 0 || y !== this.#canvas.height || this.#dirtyTransform) this.#unsupported('translate', x, y);
    this.#dirtyTransform = true;
  }

  scale(x, y) {
    if (x !== 1 || y !== -1 || !this.#dirtyTransform) this.#unsupported('scale', x, y);
    this.#flipY = true;
  }

  #unsupported(name, ...args) {
    throw new Error(`canvas polyfill: only translate(0, height) then scale(1, -1) is supported, got ${name}(${args.join(', ')})`);
  }

  #pixelsOf(image) {
    if (image instanceof HTMLImageElement) return image.pixels;
    if (image instanceof HTMLCanvasElement) return image.pixels;
    throw new Error('canvas polyfill: drawImage needs an HTMLImageElement or HTMLCanvasElement');
  }

  drawImage(image, dx, dy, dw = image.width, dh = image.height) {
    const c = this.#canvas;
    if (arguments.length !== 3 && arguments.length !== 5) throw new Error('canvas polyfill: drawImage(image, dx, dy[, dw, dh]) only');
    if (dx !== 0 || dy !== 0 || dw !== c.width || dh !== c.height)
      throw new Error('canvas polyfill: drawImage must cover the whole canvas');
    if (this.#dirtyTransform && !this.#flipY) this.#unsupported('translate without scale');
    const src = this.#pixelsOf(image);
    const out = resample(src, image.width, image.height, dw, dh, this.#flipY);
    // Source-over onto the canvas; GLTFExporter draws onto fresh (transparent) or opaque canvases.
    const dst = c.pixels;
    for (let i = 0; i < dst.length; i += 4) {
      const sa = out[i + 3] / 255, da = dst[i + 3] / 255;
      const oa = sa + da * (1 - sa);
      if (oa === 0) { dst[i] = out[i]; dst[i + 1] = out[i + 1]; dst[i + 2] = out[i + 2]; dst[i + 3] = 0; continue; }
      for (let k = 0; k < 3; k++) dst[i + k] = Math.round((out[i + k] * sa + dst[i + k] * da * (1 - sa)) / oa);
      dst[i + 3] = Math.round(oa * 255);
    }
  }

  fillRect(x, y, w, h) {
    const m = /^#([0-9a-f]{6})$/i.exec(this.fillStyle);
    if (!m) throw new Error(`canvas polyfill: fillStyle must be '#rrggbb', got '${this.fillStyle}'`);
    const v = parseInt(m[1], 16);
    const c = this.#canvas, dst = c.pixels;
    for (let yy = Math.max(0, y); yy < Math.min(c.height, y + h); yy++)
      for (let xx = Math.max(0, x); xx < Math.min(c.width, x + w); xx++) {
        const i = (yy * c.width + xx) * 4;
        dst[i] = v >> 16; dst[i + 1] = (v >> 8) & 255; dst[i + 2] = v & 255; dst[i + 3] = 255;
      }
  }

  getImageData(x, y, w, h) {
    const c = this.#canvas;
    if (x !== 0 || y !== 0 || w !== c.width || h !== c.height) throw new Error('canvas polyfill: getImageData of the whole canvas only');
    return new ImageData(new Uint8ClampedArray(c.pixels), w, h);
  }

  putImageData(imageData, x, y) {
    const c = this.#canvas;
    if (x !== 0 || y !== 0 || imageData.width !== c.width || imageData.height !== c.height)
      throw new Error('canvas polyfill: putImageData of the whole canvas only');
    c.pixels.set(imageData.data);
  }
}

export class HTMLCanvasElement {
  #width = 300;
  #height = 150;
  #pixels = null;
  #context = null;

  get width() { return this.#width; }
  set width(v) { this.#width = v >>> 0; this.#pixels = null; }
  get height() { return this.#height; }
  set height(v) { this.#height = v >>> 0; this.#pixels = null; }

  /** Straight RGBA8, transparent black when (re)sized. */
  get pixels() {
    if (!this.#pixels) this.#pixels = new Uint8ClampedArray(this.#width * this.#height * 4);
    return this.#pixels;
  }

  getContext(type) {
    if (type !== '2d') return null;
    if (!this.#context) this.#context = new CanvasRenderingContext2D(this);
    return this.#context;
  }

  toBlob(callback, type = 'image/png', quality) {
    let bytes;
    if (type === 'image/png') bytes = encodePng(this.pixels, this.#width, this.#height);
    else if (type === 'image/jpeg') bytes = encodeJpeg(this.pixels, this.#width, this.#height, Math.round((quality ?? 0.92) * 100));
    else throw new Error(`canvas polyfill: toBlob cannot write ${type}`);
    const blob = new Blob([bytes], { type });
    setImmediate(() => callback(blob));
  }
}

let readQueue = Promise.resolve();

export class FileReader {
  result = null;
  error = null;
  readyState = 0;
  onload = null;
  onloadend = null;
  onerror = null;

  #read(blob, convert) {
    this.readyState = 1;
    readQueue = readQueue.then(async () => {
      try {
        this.result = convert(await blob.arrayBuffer(), blob);
        this.readyState = 2;
        if (this.onload) this.onload({ target: this });
      } catch (error) {
        this.error = error;
        this.readyState = 2;
        if (this.onerror) this.onerror({ target: this });
      }
      if (this.onloadend) this.onloadend({ target: this });
    });
  }

  readAsArrayBuffer(blob) { this.#read(blob, (ab) => ab); }

  readAsDataURL(blob) {
    this.#read(blob, (ab, b) => `data:${b.type || 'application/octet-stream'};base64,` + Buffer.from(ab).toString('base64'));
  }
}

const document = {
  createElementNS(ns, name) { return document.createElement(name); },
  createElement(name) {
    if (name === 'img') return new HTMLImageElement();
    if (name === 'canvas') return new HTMLCanvasElement();
    throw new Error(`document polyfill: cannot create <${name}>`);
  },
};

/** Install the stand-ins on globalThis; call before importing ez-tree. */
export function installBrowserPolyfills() {
  for (const name of ['document', 'HTMLImageElement', 'HTMLCanvasElement', 'ImageData', 'FileReader']) {
    if (name in globalThis) throw new Error(`${name} already exists; refusing to replace it`);
  }
  Object.assign(globalThis, { document, HTMLImageElement, HTMLCanvasElement, ImageData, FileReader });
}
