"""The reference values of oracle.tsv: the mean LDR-FLIP of NVIDIA's flip-evaluator and
the SSIM of scikit-image for every pair DIR/NAME.ref.png, DIR/NAME.test.png, as a table
on standard output. Usage: python oracle.py DIR"""

import os
import sys
from importlib.metadata import version

import numpy as np
import flip_evaluator as flip
from skimage.metrics import structural_similarity

pairs_dir = sys.argv[1]
names = sorted(f[: -len(".ref.png")] for f in os.listdir(pairs_dir) if f.endswith(".ref.png"))

print("# The mean LDR-FLIP (default viewing: 0.7 m, 0.7 m wide, 3840 pixels) and the SSIM of")
print("# each pair of test/flip/pairs/ (NAME.ref.png against NAME.test.png), by the reference")
print("# implementations; made by `bash test/flip/oracle.sh` (`make flip-oracle`), not by hand:")
print("#   flip: flip-evaluator %s, flip_evaluator.evaluate(REF, TEST, \"LDR\")[1]" % version("flip-evaluator"))
print("#   ssim: scikit-image %s, skimage.metrics.structural_similarity(REF, TEST," % version("scikit-image"))
print("#         gaussian_weights=True, sigma=1.5, use_sample_covariance=False, data_range=255,")
print("#         channel_axis=2) on the 8-bit values; - where an image is under 11x11")
print("#   (numpy %s, Python %d.%d)" % (version("numpy"), sys.version_info[0], sys.version_info[1]))
print("# pair\tflip\tssim")
for name in names:
    ref = os.path.join(pairs_dir, name + ".ref.png")
    test = os.path.join(pairs_dir, name + ".test.png")
    _, mean, _ = flip.evaluate(ref, test, "LDR")
    a = np.rint(flip.load(ref) * 255.0).astype(np.uint8)
    b = np.rint(flip.load(test) * 255.0).astype(np.uint8)
    if min(a.shape[0], a.shape[1]) >= 11:
        s = "%.6f" % structural_similarity(
            a, b, gaussian_weights=True, sigma=1.5, use_sample_covariance=False,
            data_range=255, channel_axis=2)
    else:
        s = "-"
    print("%s\t%.6f\t%s" % (name, mean, s))
