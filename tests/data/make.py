#!/usr/bin/env python3
"""Writes the small NumPy and CSV fixtures read by faint-host's io::input tests.

Run from anywhere: `python3 tests/data/make.py` (needs numpy). The outputs are committed,
so the Rust tests never need Python. Every value follows a formula the tests recompute:

  complex frames  z[k, i]       = (100 k + i) + 0.25 i j
  complex128      z[k, i]       = (100 k + i + 0.1) + 0.25 i j   (0.1 tests the narrowing)
  cube            v[k, r, d, a] = 1000 k + 100 r + 10 d + a + 0.5
  image           v[k, r, c]    = 100 k + 10 r + c + 0.25
"""
import os

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))


def path(name):
    return os.path.join(HERE, name)


def save(name, a, fortran=None):
    np.save(path(name), a)
    # Check the order numpy actually wrote, so a fixture cannot silently be C order.
    with open(path(name), "rb") as f:
        major, _ = np.lib.format.read_magic(f)
        read_header = (np.lib.format.read_array_header_1_0 if major == 1
                       else np.lib.format.read_array_header_2_0)
        _, fortran_order, _ = read_header(f)
    if fortran is not None:
        assert fortran_order == fortran, (name, fortran_order)


def complex_frames(K=3, m=8, dtype=np.complex64):
    k, i = np.meshgrid(np.arange(K), np.arange(m), indexing="ij")
    return ((100 * k + i) + 0.25j * i).astype(dtype)


def iq(z, dtype=np.float32):
    return np.stack([z.real, z.imag], axis=-1).astype(dtype)


def main():
    z = complex_frames()
    save("complex_c.npy", z, fortran=False)
    save("complex_f.npy", np.asfortranarray(z), fortran=True)
    save("complex_be.npy", z.astype(">c8"), fortran=False)
    save("iq_c.npy", iq(z), fortran=False)
    save("iq_f.npy", np.asfortranarray(iq(z)), fortran=True)
    save("iq_f64.npy", iq(z, np.float64), fortran=False)

    k, i = np.meshgrid(np.arange(2), np.arange(4), indexing="ij")
    save("complex128.npy", ((100 * k + i + 0.1) + 0.25j * i).astype(np.complex128), fortran=False)

    cube = np.fromfunction(lambda k, r, d, a: 1000 * k + 100 * r + 10 * d + a + 0.5,
                           (2, 3, 4, 5)).astype(np.float32)
    save("cube_c.npy", cube, fortran=False)
    save("cube_f.npy", np.asfortranarray(cube), fortran=True)

    image = np.fromfunction(lambda k, r, c: 100 * k + 10 * r + c + 0.25, (2, 6, 6))
    save("image.npy", image.astype(np.float32), fortran=False)
    save("image_f64.npy", np.asfortranarray(image.astype(np.float64)), fortran=True)

    np.savez(path("frames.npz"), meta=np.arange(3), frames=z)
    np.savez_compressed(path("single.npz"), z)
    np.savez(path("ambiguous.npz"), a=z, b=z)

    # Bad files.
    with open(path("complex_c.npy"), "rb") as f:
        good = f.read()
    with open(path("truncated.npy"), "wb") as f:
        f.write(good[: len(good) - 20])
    with open(path("text.npy"), "w") as f:
        f.write("this is not a numpy file\n")
    save("int32.npy", np.arange(24, dtype=np.int32).reshape(3, 8))
    save("rank1.npy", np.arange(3).astype(np.complex64))
    save("rank3.npy", np.zeros((3, 4, 5), dtype=np.complex64))
    save("empty.npy", np.zeros((0, 8), dtype=np.complex64))
    bad = complex_frames()
    bad[1, 5] = np.nan
    save("nan.npy", bad)
    bad = iq(complex_frames())
    bad[2, 3, 1] = np.inf
    save("iq_inf.npy", bad)

    # Plot lists: scans 0-based; "3,,," marks scan 3 as present with no plots.
    csvs = {
        "plots.csv": "scan,amplitude,x,y\n0,1.5,10,20\n0,2.25,-3.5,4\n2,3,100.125,-7\n3,,,\n",
        "plots_header.csv": "scan,amp,x,y\n0,1.5,10,20\n",
        "plots_nan.csv": "scan,amplitude,x,y\n0,1.5,10,20\n1,NaN,10,20\n",
        "plots_text.csv": "scan,amplitude,x,y\n0,1.5,10,20\n0,2,abc,20\n",
        "plots_decreasing.csv": "scan,amplitude,x,y\n0,1.5,10,20\n2,1,1,1\n1,1,1,1\n",
        "plots_columns.csv": "scan,amplitude,x,y\n0,1.5,10,20\n1,1.5,10,20,7\n",
    }
    for name, text in csvs.items():
        with open(path(name), "w", newline="") as f:
            f.write(text)


if __name__ == "__main__":
    main()
