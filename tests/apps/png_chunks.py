# Lists a PNG's chunks for display_image_test.sh: one line per chunk, "TYPE" plus its decoded
# content for IHDR (width height bit-depth colour-type), oFFs (x y unit), gAMA, sRGB and tEXt
# (key=value). Exits 1 if the file is not a PNG or a chunk's CRC is wrong.
import struct
import sys
import zlib

data = open(sys.argv[1], "rb").read()
if data[:8] != b"\x89PNG\r\n\x1a\n":
    sys.exit("not a PNG")
pos = 8
while pos < len(data):
    (length,) = struct.unpack(">I", data[pos:pos + 4])
    kind = data[pos + 4:pos + 8]
    body = data[pos + 8:pos + 8 + length]
    (crc,) = struct.unpack(">I", data[pos + 8 + length:pos + 12 + length])
    if zlib.crc32(kind + body) != crc:
        sys.exit("bad CRC in " + kind.decode("latin-1"))
    name = kind.decode("latin-1")
    if name == "IHDR":
        w, h, depth, colour = struct.unpack(">IIBB", body[:10])
        print("IHDR", w, h, depth, colour)
    elif name == "oFFs":
        x, y, unit = struct.unpack(">iiB", body)
        print("oFFs", x, y, unit)
    elif name == "gAMA":
        print("gAMA", struct.unpack(">I", body)[0])
    elif name == "sRGB":
        print("sRGB", body[0])
    elif name == "tEXt":
        key, _, value = body.partition(b"\0")
        print("tEXt", key.decode("latin-1") + "=" + value.decode("latin-1"))
    elif name != "IDAT":
        print(name)
    pos += 12 + length
