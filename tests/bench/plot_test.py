#!/usr/bin/env python3
"""bench/plot.py on hand-made plot data: each PNG is written at 960x600, a line's colour shows
where its data are, a series with gaps and a marker row still draw, and a plot without data
is still written. Exits 77 (skipped for ctest) when matplotlib is not installed.

usage: plot_test.py PLOT_PY OUTDIR
"""
import json
import os
import shutil
import subprocess
import sys
import unittest

PLOT_PY, OUT = sys.argv[1], sys.argv[2]


def write(name, text):
    with open(os.path.join(OUT, name), "w") as f:
        f.write(text)


class PlotScript(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        shutil.rmtree(OUT, ignore_errors=True)
        os.makedirs(OUT)
        # A rising line with a gap (an untimed frame) on a log y axis.
        write("line.csv", "series,label,time_s,frame_ms\n"
                          '"a","technique a",0,1\n"a","technique a",1,\n"a","technique a",2,10\n'
                          '"a","technique a",3,100\n')
        # A curve with labels that hold commas, and two marked points.
        write("trade.csv", "series,label,lod_bias,median_frame_ms,mean_flip,marker\n"
                           '"mesh","polygonal reference (mesh, 1 spp)",1,8,0,o\n'
                           '"quad","floor: the Forest\'s one-quad level",1,0.5,0.4,s\n'
                           '"auto","auto (LoD bias 1,0.5)",1,2,0.05,\n"auto","auto (LoD bias 1,0.5)",0.5,1,0.1,\n')
        write("empty.csv", "series,label,trees,median_frame_ms\n")
        plots = [
            {"csv": "line.csv", "png": "line.png", "x": "time_s", "y": "frame_ms", "title": "line",
             "xLabel": "path time (s)", "yLabel": "frame ms", "logX": False, "logY": True, "markers": False},
            {"csv": "trade.csv", "png": "trade.png", "x": "median_frame_ms", "y": "mean_flip", "title": "trade",
             "xLabel": "ms", "yLabel": "FLIP", "logX": True, "logY": False, "markers": True},
            {"csv": "empty.csv", "png": "empty.png", "x": "trees", "y": "median_frame_ms", "title": "empty",
             "xLabel": "trees", "yLabel": "ms", "logX": True, "logY": True, "markers": True},
        ]
        write("plots.json", json.dumps({"plots": plots}))
        cls.result = subprocess.run([sys.executable, PLOT_PY, OUT], capture_output=True, text=True)

    def image(self, name):
        import matplotlib.image
        return matplotlib.image.imread(os.path.join(OUT, name))

    def test_exitsCleanly(self):
        self.assertEqual(self.result.returncode, 0, self.result.stderr)
        self.assertEqual(self.result.stdout, "")

    def test_everyPlotIsA960x600Png(self):
        for name in ("line.png", "trade.png", "empty.png"):
            with open(os.path.join(OUT, name), "rb") as f:
                self.assertEqual(f.read(8), b"\x89PNG\r\n\x1a\n", name)
            self.assertEqual(self.image(name).shape[:2], (600, 960), name)

    def test_lineDrawnInTheFirstColour(self):
        # matplotlib's first colour, #1f77b4: the line's pixels are there; none in the empty plot.
        def blue(img):
            r, g, b = img[..., 0], img[..., 1], img[..., 2]
            return int(((abs(r - 0x1f / 255) < 0.05) & (abs(g - 0x77 / 255) < 0.05) & (abs(b - 0xb4 / 255) < 0.05)).sum())
        self.assertGreater(blue(self.image("line.png")), 200)
        self.assertGreater(blue(self.image("trade.png")), 50)
        self.assertEqual(blue(self.image("empty.png")), 0)

    def test_missingManifestFails(self):
        empty = os.path.join(OUT, "no-manifest")
        os.makedirs(empty, exist_ok=True)
        run = subprocess.run([sys.executable, PLOT_PY, empty], capture_output=True, text=True)
        self.assertEqual(run.returncode, 2)
        self.assertIn("plots.json", run.stderr)


if __name__ == "__main__":
    try:
        import matplotlib  # noqa: F401
    except ImportError:
        print("matplotlib not installed: bench/plot.py not tested")
        sys.exit(77)
    sys.argv[1:] = []
    unittest.main(verbosity=2)
