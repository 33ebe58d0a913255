// Grey PNGs for 2-D coarse profiles (the library reads 8/16-bit grey PNGs
// without alpha, docs/format.md "2-D surfaces"): any image the browser can
// decode is turned into 8-bit grey (Rec. 709 luma, transparent parts over
// white), and a painted grey canvas is encoded the same way. The encoder is
// the PNG format's minimum: IHDR, one zlib IDAT (the browser's
// CompressionStream 'deflate' is zlib), IEND, filter 0 on every row.

const crcTable = (() => {
  const t = new Uint32Array(256);
  for (let n = 0; n < 256; n++) {
    let c = n;
    for (let k = 0; k < 8; k++) c = c & 1 ? 0xedb88320 ^ (c >>> 1) : c >>> 1;
    t[n] = c >>> 0;
  }
  return t;
})();

function crc32(bytes: Uint8Array): number {
  let c = 0xffffffff;
  for (const b of bytes) c = crcTable[(c ^ b) & 0xff] ^ (c >>> 8);
  return (c ^ 0xffffffff) >>> 0;
}

function chunk(type: string, data: Uint8Array): Uint8Array {
  const out = new Uint8Array(12 + data.length);
  const dv = new DataView(out.buffer);
  dv.setUint32(0, data.length);
  for (let i = 0; i < 4; i++) out[4 + i] = type.charCodeAt(i);
  out.set(data, 8);
  dv.setUint32(8 + data.length, crc32(out.subarray(4, 8 + data.length)));
  return out;
}

async function deflate(bytes: Uint8Array): Promise<Uint8Array> {
  const stream = new Blob([bytes as BlobPart]).stream().pipeThrough(new CompressionStream('deflate'));
  return new Uint8Array(await new Response(stream).arrayBuffer());
}

/** An 8-bit grey PNG of `grey` (width·height bytes, row-major). */
export async function greyPng(grey: Uint8Array, width: number, height: number): Promise<Uint8Array> {
  const raw = new Uint8Array((width + 1) * height);
  for (let j = 0; j < height; j++) raw.set(grey.subarray(j * width, (j + 1) * width), j * (width + 1) + 1);
  const ihdr = new Uint8Array(13);
  const dv = new DataView(ihdr.buffer);
  dv.setUint32(0, width);
  dv.setUint32(4, height);
  ihdr.set([8, 0, 0, 0, 0], 8); // depth 8, colour type 0 (grey), deflate, filter 0, no interlace
  const parts = [new Uint8Array([0x89, 0x50, 0x4e, 0x47, 0x0d, 0x0a, 0x1a, 0x0a]), chunk('IHDR', ihdr), chunk('IDAT', await deflate(raw)), chunk('IEND', new Uint8Array(0))];
  const out = new Uint8Array(parts.reduce((n, p) => n + p.length, 0));
  let at = 0;
  for (const p of parts) {
    out.set(p, at);
    at += p.length;
  }
  return out;
}

/** The grey levels of a canvas's pixels (luma, transparent over white). */
export function greyOf(ctx: CanvasRenderingContext2D, width: number, height: number): Uint8Array {
  const d = ctx.getImageData(0, 0, width, height).data;
  const g = new Uint8Array(width * height);
  for (let i = 0; i < g.length; i++) {
    const a = d[4 * i + 3] / 255;
    const luma = 0.2126 * d[4 * i] + 0.7152 * d[4 * i + 1] + 0.0722 * d[4 * i + 2];
    g[i] = Math.round(luma * a + 255 * (1 - a));
  }
  return g;
}

/** Any image file the browser decodes → an 8-bit grey PNG of the same size (at most 4096 px a side). */
export async function toGreyPng(file: Blob): Promise<{ png: Uint8Array; width: number; height: number }> {
  const bmp = await createImageBitmap(file);
  const f = Math.min(1, 4096 / Math.max(bmp.width, bmp.height));
  const width = Math.max(1, Math.round(bmp.width * f));
  const height = Math.max(1, Math.round(bmp.height * f));
  const c = document.createElement('canvas');
  c.width = width;
  c.height = height;
  const ctx = c.getContext('2d', { willReadFrequently: true })!;
  ctx.drawImage(bmp, 0, 0, width, height);
  bmp.close();
  return { png: await greyPng(greyOf(ctx, width, height), width, height), width, height };
}
