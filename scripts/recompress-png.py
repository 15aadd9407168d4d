#!/usr/bin/env python3
"""Lossless recompression of a robomach plot for docs/img/: the same pixels,
stored as a palette image when the plot has at most 256 colours, otherwise
as RGB(A) with the PNG row filter chosen per row (least sum of absolute
differences) and zlib level 9. The tools' PNGs (OpenCV, fast compression) shrink
by 30-60 %, so the README's pictures stay under the 150 kB the docs.links
test allows. Reads 8-bit RGB or RGBA, non-interlaced (what the tools write);
checks that the written file decodes to the same pixels.

Usage: scripts/recompress-png.py IN.png OUT.png
"""
import struct
import sys
import zlib


def chunks(data):
    i = 8
    while i < len(data):
        n, = struct.unpack('>I', data[i:i + 4])
        yield data[i + 4:i + 8], data[i + 8:i + 8 + n]
        i += 12 + n


def paeth(a, b, c):
    p = a + b - c
    pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
    return a if pa <= pb and pa <= pc else (b if pb <= pc else c)


def predictor(f, a, b, c):
    return (0, a, b, (a + b) >> 1, paeth(a, b, c))[f]


def decode(path):
    """Pixels of an 8-bit non-interlaced PNG as rows of RGB(A) bytes."""
    data = open(path, 'rb').read()
    if data[:8] != b'\x89PNG\r\n\x1a\n':
        sys.exit(f'{path}: not a PNG file')
    idat, palette, alpha = b'', None, None
    for kind, body in chunks(data):
        if kind == b'IHDR':
            w, h, depth, colour, _, _, interlace = struct.unpack('>IIBBBBB', body)
        elif kind == b'IDAT':
            idat += body
        elif kind == b'PLTE':
            palette = [body[i:i + 3] for i in range(0, len(body), 3)]
        elif kind == b'tRNS':
            alpha = body
    if depth != 8 or interlace != 0 or colour not in (2, 3, 6):
        sys.exit(f'{path}: only 8-bit non-interlaced RGB, RGBA or palette PNGs (depth {depth}, '
                 f'colour type {colour}, interlace {interlace})')
    bpp = {2: 3, 3: 1, 6: 4}[colour]
    raw, stride, rows, prev, i = zlib.decompress(idat), w * bpp, [], bytearray(w * bpp), 0
    for _ in range(h):
        f, line = raw[i], bytearray(raw[i + 1:i + 1 + stride])
        i += 1 + stride
        for x in range(stride):
            a = line[x - bpp] if x >= bpp else 0
            c = prev[x - bpp] if x >= bpp else 0
            line[x] = (line[x] + predictor(f, a, prev[x], c)) & 255
        rows.append(bytes(line))
        prev = line
    if colour == 3:
        if alpha:
            palette = [p + bytes([alpha[k] if k < len(alpha) else 255]) for k, p in enumerate(palette)]
        rows = [b''.join(palette[v] for v in r) for r in rows]
        bpp = len(palette[0])
    return w, h, bpp, rows


def filtered(rows, bpp):
    out, prev = bytearray(), bytes(len(rows[0]))
    for line in rows:
        best = None
        for f in range(5):
            r = bytearray(len(line))
            for x in range(len(line)):
                a = line[x - bpp] if x >= bpp else 0
                c = prev[x - bpp] if x >= bpp else 0
                r[x] = (line[x] - predictor(f, a, prev[x], c)) & 255
            cost = sum(v if v < 128 else 256 - v for v in r)
            if best is None or cost < best[0]:
                best = (cost, f, r)
        out.append(best[1])
        out += best[2]
        prev = line
    return bytes(out)


def chunk(kind, body):
    return struct.pack('>I', len(body)) + kind + body + struct.pack('>I', zlib.crc32(kind + body) & 0xffffffff)


def encode(w, h, bpp, rows):
    colours = {}
    for r in rows:
        for x in range(0, len(r), bpp):
            colours.setdefault(r[x:x + bpp], None)
        if len(colours) > 256:
            break
    out = b'\x89PNG\r\n\x1a\n'
    if len(colours) <= 256:
        palette = sorted(colours)
        index = {c: k for k, c in enumerate(palette)}
        out += chunk(b'IHDR', struct.pack('>IIBBBBB', w, h, 8, 3, 0, 0, 0))
        out += chunk(b'PLTE', b''.join(c[:3] for c in palette))
        if bpp == 4:
            out += chunk(b'tRNS', bytes(c[3] for c in palette))
        body = b''.join(b'\x00' + bytes(index[r[x:x + bpp]] for x in range(0, len(r), bpp)) for r in rows)
    else:
        out += chunk(b'IHDR', struct.pack('>IIBBBBB', w, h, 8, 2 if bpp == 3 else 6, 0, 0, 0))
        body = filtered(rows, bpp)
    return out + chunk(b'IDAT', zlib.compress(body, 9)) + chunk(b'IEND', b'')


def main():
    if len(sys.argv) != 3:
        sys.exit('usage: recompress-png.py IN.png OUT.png')
    source, target = sys.argv[1], sys.argv[2]
    image = decode(source)
    data = encode(*image)
    tmp = target + '.tmp'
    with open(tmp, 'wb') as f:
        f.write(data)
    if decode(tmp) != image:
        sys.exit(f'recompress-png: internal error: {tmp} does not decode to the pixels of {source}')
    import os
    os.replace(tmp, target)
    print(f'{target}: {image[0]} x {image[1]}, {os.path.getsize(source)} -> {len(data)} bytes, same pixels')


if __name__ == '__main__':
    main()
