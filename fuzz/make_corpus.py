#!/usr/bin/env python3
"""Writes the seed corpora of the fuzz harnesses into fuzz/corpus/<harness>/ (small,
committed; rerun after changing it). Seeds are valid inputs of each reader in the forms
its tests use, plus the shared blob's cameras.json; crashes found later are added by hand
next to them (crash-<what>)."""
import json
import os
import struct
import sys
import zlib

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "corpus")
SHARED = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "shared")


def write(harness, name, data):
    folder = os.path.join(ROOT, harness)
    os.makedirs(folder, exist_ok=True)
    with open(os.path.join(folder, name), "wb") as f:
        f.write(data if isinstance(data, bytes) else data.encode())


def png(width, height, channels=1, depth=8, value=lambda x, y, c: (x * 37 + y * 11 + c * 5) % 256):
    colour_type = {1: 0, 2: 4, 3: 2, 4: 6}[channels]
    rows = b""
    for y in range(height):
        row = bytearray([0])
        for x in range(width):
            for c in range(channels):
                v = value(x, y, c)
                row += struct.pack(">H", v * 257) if depth == 16 else bytes([v])
        rows += bytes(row)
    def chunk(kind, body):
        return struct.pack(">I", len(body)) + kind + body + struct.pack(">I", zlib.crc32(kind + body))
    header = struct.pack(">IIBBBBB", width, height, depth, colour_type, 0, 0, 0)
    return b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", header) + chunk(b"IDAT", zlib.compress(rows)) + chunk(b"IEND", b"")


def tree(files):
    out = b""
    for name, content in files:
        out += b"==> " + name.encode() + b" <==\n" + (content if isinstance(content, bytes) else content.encode()) + b"\n"
    return out


CUBE_V = [(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0), (0, 0, 1), (1, 0, 1), (1, 1, 1), (0, 1, 1)]
CUBE_QUADS = [(0, 3, 2, 1), (4, 5, 6, 7), (0, 1, 5, 4), (1, 2, 6, 5), (2, 3, 7, 6), (3, 0, 4, 7)]
TETRA_V = [(0, 0, 0), (1, 0, 0), (0, 1, 0), (0, 0, 1)]
TETRA_F = [(0, 2, 1), (0, 1, 3), (0, 3, 2), (1, 2, 3)]


def ply_ascii(vertices, faces, extra=False):
    head = "ply\nformat ascii 1.0\ncomment seed\nelement vertex %d\nproperty float x\nproperty float y\nproperty float z\n" % len(vertices)
    if extra:
        head += "property float vx\nproperty uchar red\n"
    head += "element face %d\nproperty list uchar int vertex_indices\nend_header\n" % len(faces)
    body = "".join(" ".join("%g" % c for c in v) + (" 0.5 200" if extra else "") + "\n" for v in vertices)
    body += "".join("%d %s\n" % (len(f), " ".join(map(str, f))) for f in faces)
    return head + body


def ply_binary(vertices, faces, big_endian, index_type="int"):
    order = ">" if big_endian else "<"
    kind = "binary_big_endian" if big_endian else "binary_little_endian"
    code = {"int": "i", "uint": "I", "ushort": "H", "short": "h"}[index_type]
    head = ("ply\nformat %s 1.0\nelement vertex %d\nproperty double x\nproperty double y\nproperty double z\n"
            "property uchar quality\nelement face %d\nproperty list uchar %s vertex_indices\n"
            "element edge 1\nproperty int vertex1\nproperty int vertex2\nend_header\n") % (kind, len(vertices), len(faces), index_type)
    body = b"".join(struct.pack(order + "dddB", *v, 7) for v in vertices)
    body += b"".join(struct.pack(order + "B" + code * len(f), len(f), *f) for f in faces)
    body += struct.pack(order + "ii", 0, 1)
    return head.encode() + body


def obj(vertices, faces, style=0):
    text = "# seed\no mesh\n" + "".join("v %g %g %g\n" % v for v in vertices) + "vt 0 0\nvn 0 0 1\n"
    for f in faces:
        if style == 0:
            text += "f " + " ".join(str(i + 1) for i in f) + "\n"
        elif style == 1:
            text += "f " + " ".join("%d/1/1" % (i + 1) for i in f) + "\n"
        else:
            text += "f " + " ".join(str(i - len(vertices)) for i in f) + "\n"
    return text


def cameras_json(names, width, height, frame_count=None, bounds=True):
    cameras = []
    for k, name in enumerate(names):
        cameras.append({"name": name, "width": width, "height": height,
                        "K": [[40.0, 0.0, (width - 1) / 2], [0.0, 40.0, (height - 1) / 2], [0.0, 0.0, 1.0]],
                        "R": [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]] if k == 0 else
                             [[0.0, 0.0, -1.0], [0.0, 1.0, 0.0], [1.0, 0.0, 0.0]],
                        "t": [0.0, 0.0, 2.0], "distortion": [0.01, -0.002, 0.0, 0.0, 0.0]})
    root = {"format": "multiview-video/1", "fps": 30, "units": "meters", "cameras": cameras}
    if frame_count:
        root["frame_count"] = frame_count
    if bounds:
        root["bounds"] = {"min": [-0.5, -0.5, -0.5], "max": [0.5, 0.5, 0.5]}
    return json.dumps(root, indent=1)


def main():
    # cameras.json
    write("cameras_json_fuzzer", "small.json", cameras_json(["left", "right"], 16, 12, frame_count=3))
    write("cameras_json_fuzzer", "no_bounds.json", cameras_json(["a"], 8, 6, bounds=False))
    blob = os.path.join(SHARED, "data", "blob", "cameras.json")
    if os.path.exists(blob):
        with open(blob, "rb") as f:
            write("cameras_json_fuzzer", "blob.json", f.read())
    # PLY
    write("ply_fuzzer", "tetra_ascii.ply", ply_ascii(TETRA_V, TETRA_F, extra=True))
    write("ply_fuzzer", "cube_quads_ascii.ply", ply_ascii(CUBE_V, CUBE_QUADS))
    write("ply_fuzzer", "tetra_le.ply", ply_binary(TETRA_V, TETRA_F, False))
    write("ply_fuzzer", "cube_quads_be.ply", ply_binary(CUBE_V, CUBE_QUADS, True, "uint"))
    write("ply_fuzzer", "tetra_be_ushort.ply", ply_binary(TETRA_V, TETRA_F, True, "ushort"))
    # OBJ
    write("obj_fuzzer", "tetra.obj", obj(TETRA_V, TETRA_F))
    write("obj_fuzzer", "cube_quads.obj", obj(CUBE_V, CUBE_QUADS, style=1))
    write("obj_fuzzer", "tetra_relative.obj", obj(TETRA_V, TETRA_F, style=2))
    write("obj_fuzzer", "lshape_ngon.obj", "v 0 0 0\nv 2 0 0\nv 2 1 0\nv 1 1 0\nv 1 2 0\nv 0 2 0\nf 1 2 3 4 5 6\n")
    # Dataset layouts: images (8-bit gray, colour, 16-bit), masks, background, ground truth.
    w, h = 8, 6
    files = [("cameras.json", cameras_json(["left", "right"], w, h, frame_count=2))]
    for cam, channels, depth in (("left", 1, 8), ("right", 3, 16)):
        for frame in range(2):
            files.append(("images/%s/%06d.png" % (cam, frame), png(w, h, channels, depth)))
            files.append(("masks/%s/%06d.png" % (cam, frame), png(w, h, 1, 8, lambda x, y, c: 255 if 2 < x < 6 else 0)))
        files.append(("background/%s.png" % cam, png(w, h, channels, 8, lambda x, y, c: 10)))
    write("dataset_layout_fuzzer", "images_masks_background", tree(files))
    files = [("cameras.json", cameras_json(["a"], w, h, bounds=True))]
    files += [("images/a/%06d.png" % f, png(w, h, 4)) for f in range(3)]
    files += [("groundtruth/mesh/%06d.ply" % f, ply_ascii(TETRA_V, TETRA_F)) for f in range(3)]
    write("dataset_layout_fuzzer", "rgba_groundtruth", tree(files))
    # COLMAP text model
    cameras_txt = ("# Camera list\n1 PINHOLE 64 48 50 52 32 24\n2 SIMPLE_RADIAL 64 48 50 32 24 0.01\n"
                   "3 OPENCV 64 48 50 51 32 24 0.01 -0.001 0.0001 0.0002\n")
    images_txt = ("# Image list\n1 1 0 0 0 0 0 2 1 cam00/000000.png\n10 20 C 30 40\n"
                  "2 0.7071 0 0.7071 0 0.1 0 2 2 cam01/000000.png\n\n3 0.5 0.5 0.5 0.5 0 0 3 3 cam02/000000.png\n\n")
    write("colmap_text_fuzzer", "three_models", tree([("cameras.txt", cameras_txt), ("images.txt", images_txt)]))
    # Projection matrices (DTU folder with images; Middlebury par file)
    P = "50 0 32 10\n0 50 24 20\n0 0 1 2\n"
    write("projection_matrix_fuzzer", "dtu_folder", tree([("pos_001.txt", "CONTOUR\n" + P), ("pos_002.txt", P),
                                                          ("pos_001.png", png(8, 6)), ("pos_002.png", png(8, 6, 3))]))
    write("projection_matrix_fuzzer", "middlebury", tree([
        ("scene_par.txt", "2\nimg0.png 50 0 32 0 50 24 0 0 1 1 0 0 0 1 0 0 0 1 0 0 2\n"
                          "img1.png 50 0 32 0 50 24 0 0 1 0 0 -1 0 1 0 1 0 0 0 0 2\n"),
        ("img0.png", png(8, 6)), ("img1.png", png(8, 6))]))
    # Every calibration importer (calibration_fuzzer): the COLMAP and matrix seeds, a
    # Pose2Sim TOML and a Panoptic JSON.
    write("calibration_fuzzer", "colmap", tree([("cameras.txt", cameras_txt), ("images.txt", images_txt)]))
    write("calibration_fuzzer", "dtu_folder", tree([("pos_001.txt", P), ("pos_001.png", png(8, 6))]))
    write("calibration_fuzzer", "pose2sim_toml", tree([("Calib.toml",
        '[cam_01]\nname = "cam_01"\nsize = [ 64.0, 48.0]\nmatrix = [ [ 50.0, 0.0, 32.0], [ 0.0, 50.0, 24.0], [ 0.0, 0.0, 1.0]]\n'
        'distortions = [ 0.01, 0.0, 0.0, 0.0]\nrotation = [ 0.1, 0.2, 0.3]\ntranslation = [ 0.0, 0.0, 2.0]\nfisheye = false\n\n'
        '[metadata]\nadjusted = false\nerror = 0.0\n')]))
    write("calibration_fuzzer", "panoptic_json", tree([("calibration.json", json.dumps({"cameras": [
        {"name": "00_00", "type": "hd", "resolution": [64, 48], "K": [[50, 0, 32], [0, 50, 24], [0, 0, 1]],
         "distCoef": [0.01, 0, 0, 0, 0], "R": [[1, 0, 0], [0, 1, 0], [0, 0, 1]], "t": [[0], [0], [200]]}]}))]))
    # COLMAP's binary model (cameras.bin, images.bin), little-endian as COLMAP writes it.
    cameras_bin = struct.pack("<Q", 2)
    cameras_bin += struct.pack("<IiQQ4d", 1, 1, 64, 48, 50, 52, 32, 24)  # PINHOLE
    cameras_bin += struct.pack("<IiQQ4d", 2, 2, 64, 48, 50, 32, 24, 0.01)  # SIMPLE_RADIAL
    images_bin = struct.pack("<Q", 2)
    images_bin += struct.pack("<I4d3dI", 1, 1, 0, 0, 0, 0, 0, 2, 1) + b"cam00/000000.png\0"
    images_bin += struct.pack("<Q", 1) + struct.pack("<ddq", 10, 20, -1)
    images_bin += struct.pack("<I4d3dI", 2, 0.7071, 0, 0.7071, 0, 0.1, 0, 2, 2) + b"cam01/000000.png\0"
    images_bin += struct.pack("<Q", 0)
    # (without tree()'s last newline: the last block runs to the end of the seed)
    write("calibration_fuzzer", "colmap_binary", tree([("cameras.bin", cameras_bin), ("images.bin", images_bin)])[:-1])
    # Qualisys .qca.txt (XML, QTM's 1/64-pixel units) and EasyMocap intri.yml / extri.yml.
    fov = ' bottom="767" left="0" right="1023" top="0"/>\n'
    write("calibration_fuzzer", "qualisys_qca", tree([("Calib.qca.txt",
        "<?xml version='1.0' encoding='ASCII'?>\n<calibration created=\"x\" qtm-version=\"none\" source=\"t\" type=\"regular\">\n"
        '  <results min-max-diff="0." std-dev="0."/>\n  <cameras>\n'
        '    <camera active="1" avg-residual="0.4" model="Miqus Video" point-count="99" serial="12345" viewrotation="0">\n'
        "      <fov_marker" + fov + "      <fov_marker_max" + fov + "      <fov_video" + fov + "      <fov_video_max" + fov +
        '      <transform r11="1" r12="0" r13="0" r21="0" r22="-1" r23="0" r31="0" r32="0" r33="-1" x="0" y="0" z="2000"/>\n'
        '      <intrinsic centerPointU="32768" centerPointV="24576" focalLengthU="51200" focalLengthV="51200" focallength="9.3"'
        ' radialDistortion1="0.64" radialDistortion2="0" radialDistortion3="0" sensorMaxU="65536" sensorMaxV="49152"'
        ' sensorMinU="0" sensorMinV="0" skew="0" tangentalDistortion1="0" tangentalDistortion2="0"/>\n'
        "    </camera>\n  </cameras>\n</calibration>\n")]))
    def yml_matrix(key, rows, cols, values):
        return (f"{key}: !!opencv-matrix\r\n  rows: {rows}\r\n  cols: {cols}\r\n  dt: d\r\n  data: ["
                + ", ".join(f"{v:.6f}" for v in values) + "]\r\n")
    names = '%YAML:1.0\r\n---\r\nnames:\r\n  - "01"\r\n'
    write("calibration_fuzzer", "easymocap_yml", tree([
        ("intri.yml", names + yml_matrix("K_01", 3, 3, [50, 0, 32, 0, 50, 24, 0, 0, 1]) +
         yml_matrix("dist_01", 1, 5, [0.01, 0, 0, 0, 0]) + "H_01: 48\r\nW_01: 64\r\n"),
        ("extri.yml", names + yml_matrix("R_01", 3, 1, [0, 0, 0]) +
         yml_matrix("Rot_01", 3, 3, [1, 0, 0, 0, 1, 0, 0, 0, 1]) + yml_matrix("T_01", 3, 1, [0, 0, 2]))]))
    # A result folder (result_reader_fuzzer): two frames with flow, and a report.
    flow = ply_ascii(TETRA_V, TETRA_F).replace("property float z\n", "property float z\nproperty float vx\nproperty float vy\nproperty float vz\n")
    flow = flow.replace("0 0 0\n1 0 0\n0 1 0\n0 0 1\n", "0 0 0 0.1 0 0\n1 0 0 0.1 0 0\n0 1 0 0.1 0 0\n0 0 1 0.1 0 0\n")
    write("result_reader_fuzzer", "two_frames", tree([("meshes/000000.ply", flow), ("meshes/000001.ply", flow),
                                                      ("report.json", json.dumps({"command": "reconstruct", "fps": 30, "units": "meters"}))]))
    return 0


if __name__ == "__main__":
    sys.exit(main())
