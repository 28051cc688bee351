#!/usr/bin/python3
"""Writes the peer-comparison scene's data next to this script (data/scenes/bench_peer.json uses them;
bench/peer renders it against pbrt-v4's figures of issue 14):

  bench_peer_64x64x64.nii.gz   a unit cube of 64³ voxels (NIfTI-1, uint8): density 3 inside the sphere
                               of radius 0.3 about the centre (voxel centres), 1 elsewhere
  bench_peer_extinction.csv    σt(λ) = σs + σa per unit at density 1, σs = 8·(550/λ)⁴, σa = 0.3
  bench_peer_albedo.csv        σs/σt

Tables every 1 nm over 360–830 nm (the material spectra are piecewise linear between the rows).
The output is byte-for-byte reproducible (gzip without a time stamp): run it to check the files.
"""
import gzip
import struct
from pathlib import Path

HERE = Path(__file__).resolve().parent
N = 64
RADIUS = 0.3


def nifti_uint8(voxels, n):
    hdr = bytearray(348)
    struct.pack_into("<i", hdr, 0, 348)                       # sizeof_hdr
    hdr[38] = ord("r")                                         # regular
    struct.pack_into("<8h", hdr, 40, 3, n, n, n, 1, 1, 1, 1)   # dim
    struct.pack_into("<hh", hdr, 70, 2, 8)                     # datatype DT_UINT8, bitpix
    struct.pack_into("<8f", hdr, 76, 1, 1, 1, 1, 0, 0, 0, 0)   # pixdim (qfac, spacing 1)
    struct.pack_into("<f", hdr, 108, 352.0)                    # vox_offset
    struct.pack_into("<ff", hdr, 112, 0.0, 0.0)                # scl_slope 0: values as stored
    desc = b"Prizma bench_peer: density 3 in r<0.3, else 1"
    hdr[148:148 + len(desc)] = desc
    hdr[344:348] = b"n+1\0"                                    # magic (single file)
    return bytes(hdr) + b"\0\0\0\0" + voxels                   # no extension


def main():
    vox = bytearray(N * N * N)
    for z in range(N):
        for y in range(N):
            for x in range(N):
                c = [(i + 0.5) / N - 0.5 for i in (x, y, z)]
                inside = c[0] ** 2 + c[1] ** 2 + c[2] ** 2 < RADIUS ** 2
                vox[(z * N + y) * N + x] = 3 if inside else 1
    data = nifti_uint8(bytes(vox), N)
    (HERE / "bench_peer_64x64x64.nii.gz").write_bytes(gzip.compress(data, compresslevel=9, mtime=0))

    ext = ["# bench_peer: extinction sigma_t = 8*(550/lambda)^4 + 0.3 per unit at density 1 (make_bench_peer.py)",
           "wavelength_nm,extinction"]
    alb = ["# bench_peer: albedo sigma_s/sigma_t, sigma_s = 8*(550/lambda)^4, sigma_a = 0.3 (make_bench_peer.py)",
           "wavelength_nm,albedo"]
    for lam in range(360, 831):
        s = 8.0 * (550.0 / lam) ** 4
        ext.append(f"{lam},{s + 0.3:.6f}")
        alb.append(f"{lam},{s / (s + 0.3):.6f}")
    (HERE / "bench_peer_extinction.csv").write_text("\n".join(ext) + "\n")
    (HERE / "bench_peer_albedo.csv").write_text("\n".join(alb) + "\n")


if __name__ == "__main__":
    main()
