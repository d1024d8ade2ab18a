#!/usr/bin/env python3
"""Independent C3D analog decoder (Python standard library only).

Reads one C3D file and prints its analog channels as scaled values, for the
C++ reader's test to compare against. Written from the C3D user guide
(c3d.org), not from ccsrm's reader: parameters are found by walking the
records, numbers are decoded with `struct` (DEC floats by hand), and each
value is (raw - ANALOG:OFFSET[c]) * ANALOG:SCALE[c] * ANALOG:GEN_SCALE.

Usage: c3d_analog_reference.py FILE FRAME [FRAME ...]
Output: one line "label<TAB>unit", per channel, after a line "channels N
samples_per_frame S rate R"; then per requested frame, per sample, one line
of the N scaled values ("%.9g").
"""
import struct
import sys


def main():
    path = sys.argv[1]
    frames_wanted = [int(a) for a in sys.argv[2:]]
    data = open(path, "rb").read()
    pblock = data[0]
    pstart = (pblock - 1) * 512
    proc = data[pstart + 3]
    endian = ">" if proc == 86 else "<"

    def u16(off):
        return struct.unpack(endian + "H", data[off:off + 2])[0]

    def i16(off):
        return struct.unpack(endian + "h", data[off:off + 2])[0]

    def f32(off):
        if proc == 85:  # VAX F-float: words swapped, exponent bias 128 with 0.1m mantissa
            w0, w1 = struct.unpack("<HH", data[off:off + 4])
            sign = w0 >> 15
            exp = (w0 >> 7) & 0xFF
            mant = ((w0 & 0x7F) << 16) | w1
            if exp == 0:
                return 0.0
            v = (1.0 + mant / float(1 << 23)) * 2.0 ** (exp - 129)
            return -v if sign else v
        return struct.unpack(endian + "f", data[off:off + 4])[0]

    # Walk the parameter records.
    groups = {}
    params = {}
    at = pstart + 4
    # Records end before the data (header word 9); some writers leave a
    # non-zero next-record offset on the last record.
    records_end = (u16(16) - 1) * 512
    while at < records_end:
        nlen = abs(struct.unpack("b", data[at:at + 1])[0])
        gid = struct.unpack("b", data[at + 1:at + 2])[0]
        if nlen == 0 or gid == 0:
            break
        name = data[at + 2:at + 2 + nlen].decode("latin-1").upper()
        off_at = at + 2 + nlen
        nxt = u16(off_at)
        if gid < 0:
            groups[-gid] = name
        else:
            typ = struct.unpack("b", data[off_at + 2:off_at + 3])[0]
            nd = data[off_at + 3]
            dims = list(data[off_at + 4:off_at + 4 + nd])
            count = 1
            for d in dims:
                count *= d
            dat = off_at + 4 + nd
            params[(gid, name)] = (typ, dims, count, dat)
        if nxt == 0:
            break
        at = off_at + nxt

    by_name = {}
    for (gid, name), v in params.items():
        by_name[(groups.get(gid, "?"), name)] = v

    def numbers(group, name):
        typ, dims, count, dat = by_name[(group, name)]
        out = []
        for i in range(count):
            if typ == 1:
                out.append(struct.unpack("b", data[dat + i:dat + i + 1])[0])
            elif typ == 2:
                out.append(i16(dat + 2 * i))
            else:
                out.append(f32(dat + 4 * i))
        return out

    def strings(group, name):
        typ, dims, count, dat = by_name[(group, name)]
        width = dims[0]
        n = count // width
        return [data[dat + k * width:dat + (k + 1) * width].decode("latin-1").rstrip(" \0")
                for k in range(n)]

    points = numbers("POINT", "USED")[0]
    point_scale = numbers("POINT", "SCALE")[0]
    point_rate = numbers("POINT", "RATE")[0]
    data_start = numbers("POINT", "DATA_START")[0]
    channels = numbers("ANALOG", "USED")[0]
    analog_rate = numbers("ANALOG", "RATE")[0]
    samples = int(round(analog_rate / point_rate))
    scales = numbers("ANALOG", "SCALE")[:channels]
    offsets = numbers("ANALOG", "OFFSET")[:channels]
    gen_scale = numbers("ANALOG", "GEN_SCALE")[0]
    labels = strings("ANALOG", "LABELS")[:channels]
    units = strings("ANALOG", "UNITS")[:channels] if ("ANALOG", "UNITS") in by_name else [""] * channels
    is_float = point_scale < 0
    size = 4 if is_float else 2
    frame_bytes = (points * 4 + channels * samples) * size

    print("channels %d samples_per_frame %d rate %.9g" % (channels, samples, analog_rate))
    for c in range(channels):
        print("%s\t%s" % (labels[c], units[c]))
    for f in frames_wanted:
        base = (data_start - 1) * 512 + f * frame_bytes + points * 4 * size
        for s in range(samples):
            row = []
            for c in range(channels):
                off = base + (s * channels + c) * size
                raw = f32(off) if is_float else i16(off)
                row.append("%.9g" % ((raw - offsets[c]) * scales[c] * gen_scale))
            print(" ".join(row))


if __name__ == "__main__":
    main()
