#!/usr/bin/env python3
"""Says where two sample files differ, for the golden digest tests.

    golden_diff.py FORMAT ACCEPTED NOW

FORMAT is the samples' encoding: u16le (device maps, .bin), f32le or f64le
(float maps, .f64). Prints one line: the first differing sample's index, its
value in the accepted file and now, how many samples differ and the largest
|difference| (with its index); or that the lengths differ. Exit status 0 when
the files hold the same samples, 1 otherwise.
"""
import struct
import sys

FORMATS = {"u16le": ("<H", 2), "f32le": ("<f", 4), "f64le": ("<d", 8)}


def samples(path, code, size):
    with open(path, "rb") as f:
        data = f.read()
    n = len(data) // size
    return list(struct.unpack("<%d%s" % (n, code[1]), data[: n * size])), len(data) % size


def main():
    if len(sys.argv) != 4 or sys.argv[1] not in FORMATS:
        sys.exit("usage: golden_diff.py u16le|f32le|f64le ACCEPTED NOW")
    code, size = FORMATS[sys.argv[1]]
    accepted, rest_a = samples(sys.argv[2], code, size)
    now, rest_b = samples(sys.argv[3], code, size)
    if len(accepted) != len(now) or rest_a != rest_b:
        print("%d samples now, %d accepted" % (len(now), len(accepted)), end="; ")
    first = None
    worst, worst_at, differing = 0.0, None, 0
    for i, (a, b) in enumerate(zip(accepted, now)):
        same = (a == b) if code[1] == "H" else struct.pack(code, a) == struct.pack(code, b)
        if same:
            continue
        differing += 1
        if first is None:
            first = i
        delta = abs(float(b) - float(a))
        if worst_at is None or delta > worst:
            worst, worst_at = delta, i
    if first is None:
        print("the common samples are identical" if len(accepted) != len(now) else "identical samples")
        return 0 if len(accepted) == len(now) else 1
    fmt = (lambda v: "%d" % v) if code[1] == "H" else (lambda v: repr(v))
    print(
        "first differing sample %d: accepted %s, now %s; %d of %d samples differ; max |delta| %s at sample %d"
        % (first, fmt(accepted[first]), fmt(now[first]), differing, min(len(accepted), len(now)), repr(worst), worst_at)
    )
    return 1


if __name__ == "__main__":
    sys.exit(main())
