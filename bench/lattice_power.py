"""Lattice-locked energy of a filter-scan-study orthographic image.

    AZ=180 ZOOM=4 CX=-0.15 CY=-0.33 build/filter-scan-study ch2better.nii.gz OUT ortho central,sobel8
    python3 bench/lattice_power.py OUT/ortho_central_point.png OUT/ortho_sobel8_point.png
"""
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import png_read as png  # noqa: E402

# Power of the image's luminance at the voxel period (4.15 px here: ZOOM=4 ortho,
# 0.5 mm voxels) along x and y, in a 256x256 crop of the cerebellum, relative
# to the mean luminance squared.
for path in sys.argv[1:]:
    im=png.read(path).astype(float)
    a=im[...,3] if im.shape[2]==4 else np.full(im.shape[:2],255.)
    l=im[...,:3].mean(2)
    c=l[240:496,0:256]; m=c.mean(); c=c-m
    F=np.abs(np.fft.fft2(c*np.outer(np.hanning(256),np.hanning(256))))**2/(256*256)**2
    f=np.fft.fftfreq(256)*256; R=np.hypot(f[:,None],f[None,:])
    ring=(R>256/4.6)&(R<256/3.8)
    print('%-40s voxel-period power %.3e  (rel %.2e)'%(path.split('/')[-1], F[ring].sum(), F[ring].sum()/m**2))
