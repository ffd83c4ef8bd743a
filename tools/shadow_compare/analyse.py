"""analyse.py OUT_DIR: the floor-shadow factor S = on / off per engine over the floor outside the
volume; mean and 95th percentile of |S_eevee - S_cycles|, and the high-pass RMS (stripes) of each
engine's image in the shadow and the umbra."""
import numpy as np, sys
from scipy.ndimage import gaussian_filter
d = sys.argv[1]
L = lambda n: np.load('%s/%s.npy' % (d, n))[..., :3].mean(-1)
a = np.load(d + '/vol_alpha.npy')
S, on = {}, {}
for e in ['CYCLES', 'BLENDER_EEVEE']:
    on[e], off = L(e + '_True'), L(e + '_False')
    S[e] = np.where(off > 0.02, on[e] / np.maximum(off, 1e-6), 1)
floor = (a <= 0) & (L('CYCLES_False') > 0.02)
from scipy.ndimage import binary_erosion
shadow = binary_erosion(floor, iterations=3) & ((S['CYCLES'] < 0.98) | (S['BLENDER_EEVEE'] < 0.98))
diff = np.abs(S['CYCLES'] - S['BLENDER_EEVEE'])[shadow]
print('floor-shadow px %d: |S_eevee - S_cycles| mean %.4f p95 %.4f' % (shadow.sum(), diff.mean(), np.percentile(diff, 95)))
for e in S:
    hp = on[e] - gaussian_filter(on[e], 2.0)
    print('%s: high-pass RMS of the shadowed floor %.5f (S mean %.3f)' % (e, np.sqrt((hp[shadow] ** 2).mean()), S[e][shadow].mean()))
umbra = shadow & (S['CYCLES'] < 0.3) & (S['BLENDER_EEVEE'] < 0.3)
for e in S:
    hp = on[e] - gaussian_filter(on[e], 2.0)
    print('%s umbra (%d px): high-pass RMS %.5f, mean %.5f' % (e, umbra.sum(), np.sqrt((hp[umbra] ** 2).mean()), on[e][umbra].mean()))
