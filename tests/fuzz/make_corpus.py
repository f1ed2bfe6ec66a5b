#!/usr/bin/python3
"""Writes the fuzz corpora kept in the repo: small valid seeds and deterministic mutations of them.

Usage: /usr/bin/python3 tests/fuzz/make_corpus.py [COUNT_PER_HARNESS]   (default 150; needs python3-gdal)
Rerunning it rewrites the seed-* and mut-* files of tests/fuzz/corpus/{scenario,raster,vector}/
identically (seeded). The lf-* files beside them are inputs a libFuzzer run of bench/fuzz.sh found
to reach new code (50 per harness, kept by hand); crash inputs, once fixed, go there too.
"""
import json
import os
import random
import sys

from osgeo import gdal, osr

here = os.path.dirname(os.path.abspath(__file__))
count = int(sys.argv[1]) if len(sys.argv) > 1 else 150
rng = random.Random(14)

TOKENS = [b"1e400", b"-1e400", b"NaN", b"null", b"[[[[[[[[", b"{\"a\":", b"\"\\u0000\"", b"-0", b"1e-400", b"99999999999999999999999",
          b"\xff\xfe", b"{}", b"[]", b"\"", b",", b":", b"-1", b"0", b"4294967296", b"true"]


def mutate(data: bytes) -> bytes:
    b = bytearray(data)
    for _ in range(rng.randint(1, 4)):
        op = rng.randrange(5)
        at = rng.randrange(len(b) + 1)
        if op == 0 and b:  # flip a byte
            b[min(at, len(b) - 1)] ^= 1 << rng.randrange(8)
        elif op == 1:  # insert a token
            b[at:at] = rng.choice(TOKENS)
        elif op == 2 and b:  # delete a span
            del b[at:at + rng.randint(1, 16)]
        elif op == 3:  # truncate
            del b[at:]
        else:  # duplicate a span
            span = bytes(b[at:at + rng.randint(1, 32)])
            b[at:at] = span
    return bytes(b)


def scenario_seeds():
    yield json.dumps({}).encode()
    yield json.dumps({"seed": 7, "output": "out", "density": {"r_min_m": 500, "r_max_m": 3000, "weights": [1, 1, 0, 0]}}).encode()
    yield json.dumps({"roads": {"bridges": False, "tunnels": False, "router": "bezier"}, "sites": {"mode": "manhattan"}}).encode()
    yield json.dumps({"hydro": {"fill": "breach", "flow": "mfd"}, "outputs": {"preview_width": 64}}).encode()
    yield json.dumps({"plugins": [{"id": "x", "library": "example", "params": {"a": [1, {"b": 2}]}}]}).encode()
    yield b"[" * 70 + b"]" * 70
    yield b'{"density": {"r_min_m": 1e400}}'


def raster_seeds(tmp):
    sr = osr.SpatialReference()
    sr.ImportFromEPSG(4326)
    for i, (dtype, gt) in enumerate([(gdal.GDT_Float32, (9.0, 0.01, 0, 43.0, 0, -0.01)),
                                     (gdal.GDT_Int16, (500000, 30, 0, 4000000, 0, -30)),
                                     (gdal.GDT_Byte, (0, 1, 0, 0, 0, -1))]):
        path = os.path.join(tmp, "seed%d.tif" % i)
        ds = gdal.GetDriverByName("GTiff").Create(path, 8, 6, 1, dtype)
        ds.SetGeoTransform(gt)
        ds.SetProjection(sr.ExportToWkt() if i != 1 else "")
        band = ds.GetRasterBand(1)
        band.WriteRaster(0, 0, 8, 6, bytes(rng.randrange(256) for _ in range(8 * 6 * gdal.GetDataTypeSize(dtype) // 8)))
        band.SetNoDataValue(0)
        ds = None
        yield b"\x00" + open(path, "rb").read()  # first byte 0: the harness names it .tif
    yield b"\x01ncols 3\nnrows 3\nxllcorner 9\nyllcorner 42\ncellsize 0.01\nNODATA_value -9999\n1 2 3\n4 -9999 6\n7 8 9\n"
    yield b"\x01ncols 3\nnrows 3\nxllcorner 0\nyllcorner 0\ncellsize 0\n1 2 3\n4 5 6\n7 8 9\n"
    yield (b"\x02<VRTDataset rasterXSize=\"4\" rasterYSize=\"4\"><SRS>EPSG:4326</SRS>"
           b"<GeoTransform>0, 1e-300, 0, 50, 0, -0.01</GeoTransform><VRTRasterBand dataType=\"Float32\" band=\"1\"/></VRTDataset>")


def vector_seeds():
    line = {"type": "Feature", "properties": {"from": 0, "to": 1, "kind": "roots", "kept": 1},
            "geometry": {"type": "LineString", "coordinates": [[9.30, 42.68], [9.42, 42.70]]}}
    point = {"type": "Feature", "properties": {"id": 0, "radius_m": 900, "class": 0, "population": 40000},
             "geometry": {"type": "Point", "coordinates": [9.30, 42.68]}}
    poly = {"type": "Feature", "properties": {"id": 1},
            "geometry": {"type": "Polygon", "coordinates": [[[9, 42], [9.1, 42], [9.1, 42.1], [9, 42]]]}}
    yield json.dumps({"type": "FeatureCollection", "features": [line, point]}).encode()
    yield json.dumps({"type": "FeatureCollection", "features": [point, point, point]}).encode()
    yield json.dumps({"type": "FeatureCollection", "features": [poly]}).encode()
    yield json.dumps({"type": "FeatureCollection", "crs": {"type": "name", "properties": {"name": "EPSG:32632"}},
                      "features": [{"type": "Feature", "properties": {}, "geometry": {"type": "Point", "coordinates": [5e5, 4.7e6]}}]}).encode()
    yield json.dumps({"type": "GeometryCollection", "geometries": [line["geometry"], point["geometry"]]}).encode()
    yield b'{"type": "FeatureCollection", "features": [{"type": "Feature", "geometry": {"type": "Point", "coordinates": [1e400, 91]}}]}'


def write(harness, seeds):
    folder = os.path.join(here, "corpus", harness)
    os.makedirs(folder, exist_ok=True)
    for name in os.listdir(folder):
        if name.startswith(("seed-", "mut-")):
            os.remove(os.path.join(folder, name))
    seeds = list(seeds)
    for i, s in enumerate(seeds):
        open(os.path.join(folder, "seed-%02d" % i), "wb").write(s)
    for i in range(count - len(seeds)):
        open(os.path.join(folder, "mut-%03d" % i), "wb").write(mutate(rng.choice(seeds))[:8192])


if __name__ == "__main__":
    import tempfile
    with tempfile.TemporaryDirectory() as tmp:
        write("scenario", scenario_seeds())
        write("raster", raster_seeds(tmp))
        write("vector", vector_seeds())
