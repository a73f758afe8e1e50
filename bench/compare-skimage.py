#!/usr/bin/python3
"""Side by side: `edmodel segment` on 2-D images against scikit-image's
`active_contour` (Debian package python3-skimage), in one run.

Usage: /usr/bin/python3 bench/compare-skimage.py BUILD_DIR [--repeat N] [--warm M]
  BUILD_DIR holds bin/edmodel (the project's build tree).
  --repeat N: time each run N times and keep the fastest (default 3); on the
    synthetic shapes the N rounds interleave the two tools' runs.
  --warm M: edmodel's computation is also timed M times in one process
    (edmodel segment --repeat M), as active_contour's calls are (default 20).

Cases with a known answer (anti-aliased images, 8-bit, 1 pixel = 1 mm, the
true boundary analytic): an ellipse of semi-axes (40, 28) pixels, the same
rotated by 0.5 rad, and a concave five-pointed star (radius 36 +- 10 pixels).
active_contour runs with the parameters of its documentation's example (the
astronaut's face: image smoothed by a Gaussian of 3 pixels, alpha 0.015,
beta 10, gamma 0.001, a circle of 400 points around the object), and once
more with the Gaussian of 1 pixel that edmodel uses by default; its snake
shrinks onto edges, so it starts from a circle around the object, 10 pixels
beyond its farthest point. edmodel runs with its defaults from a circle
inside the object (its documented use: the region force is estimated inside
the circle), and from the same circle as active_contour with a deflating
balloon of 0.2 pixel per iteration instead of the region force (whose
estimate needs a circle inside the object).

The examples of active_contour's documentation, without a known answer:
the circle around the astronaut's face (skimage.data.astronaut() in grey)
and the open snake with fixed ends on skimage.data.text(); the two tools'
contours are compared with each other. edmodel starts from the same
circle, with its defaults and with the deflating balloon and the
documentation's Gaussian of 3 pixels, and from the same open line with its
ends fixed (--open --fixed-boundary; its force pulls to edges, where the
snake of the example, w_line -5, is pulled to dark lines).

Measures: the mean and largest distance of a contour's points to the true
boundary (points -> curve), and the largest distance of the true boundary to
the contour (curve -> contour: a contour that skips a part of the object,
such as a snake bridging the star's valleys, shows there); time, as the
fastest of --repeat runs: for active_contour the Gaussian and the call (in
this Python process, so every run after the first finds its code and memory
warm); for edmodel its computation (force field + deformation) timed the
same way, the fastest of --warm runs in one process (edmodel segment
--repeat), its own figures on stderr in a fresh process (which pays for the
first use of its code and memory), and the whole process (reading the image,
writing the contour, starting the program). On the synthetic shapes each of
the --repeat rounds runs every case of both tools once, so that a slow phase
of a shared machine falls on both tools' runs alike.
"""
import os, re, subprocess, sys, tempfile, time
import numpy as np
from scipy.spatial import cKDTree
import skimage
from skimage import data
from skimage.color import rgb2gray
from skimage.filters import gaussian
from skimage.segmentation import active_contour

BUILD = sys.argv[1] if len(sys.argv) > 1 and not sys.argv[1].startswith('--') else 'build'
REPEAT = int(sys.argv[sys.argv.index('--repeat') + 1]) if '--repeat' in sys.argv else 3
WARM = int(sys.argv[sys.argv.index('--warm') + 1]) if '--warm' in sys.argv else 20
EDMODEL = os.path.join(BUILD, 'bin', 'edmodel')
WORK = tempfile.mkdtemp(prefix='edm-skimage-')


# --- Images and curves ---------------------------------------------------------

def write_mha(path, image):
    """A 2-D MetaImage (float, 1 mm pixels, origin 0): x is the column, y the row."""
    with open(path, 'wb') as out:
        out.write(('ObjectType = Image\nNDims = 2\nBinaryData = True\nBinaryDataByteOrderMSB = False\n'
                   'ElementSpacing = 1 1\nOffset = 0 0\nDimSize = %d %d\nElementType = MET_FLOAT\n'
                   'ElementDataFile = LOCAL\n' % (image.shape[1], image.shape[0])).encode())
        out.write(np.ascontiguousarray(image, dtype='<f4').tobytes())


def antialiased(shape, inside, sub=8):
    """8-bit image: 40 outside, 200 inside, edge pixels by the fraction of their
    sub x sub samples inside (inside(x, y) on arrays, x the column)."""
    rows, cols = shape
    offsets = (np.arange(sub) + 0.5) / sub - 0.5
    fraction = np.zeros(shape)
    y, x = np.mgrid[0:rows, 0:cols].astype(float)
    for dy in offsets:
        for dx in offsets:
            fraction += inside(x + dx, y + dy)
    fraction /= sub * sub
    return np.round(40 + 160 * fraction).astype(np.uint8)


def ellipse(cx, cy, a, b, angle=0.0):
    def curve(t):
        u, v = a * np.cos(t), b * np.sin(t)
        return np.stack([cx + np.cos(angle) * u - np.sin(angle) * v, cy + np.sin(angle) * u + np.cos(angle) * v], -1)

    def inside(x, y):
        dx, dy = x - cx, y - cy
        u = np.cos(angle) * dx + np.sin(angle) * dy
        v = -np.sin(angle) * dx + np.cos(angle) * dy
        return (u / a) ** 2 + (v / b) ** 2 <= 1.0

    return curve, inside, max(a, b)


def star(cx, cy, r0, amplitude, arms=5):
    def curve(t):
        r = r0 + amplitude * np.cos(arms * t)
        return np.stack([cx + r * np.cos(t), cy + r * np.sin(t)], -1)

    def inside(x, y):
        dx, dy = x - cx, y - cy
        return np.hypot(dx, dy) <= r0 + amplitude * np.cos(arms * np.arctan2(dy, dx))

    return curve, inside, r0 + amplitude


def distances(points, curve):
    """Points -> curve (mean, max) and curve -> polyline through the points
    (max), in pixels. The curve is sampled every 0.001 pixel or so."""
    dense = curve(np.linspace(0.0, 2.0 * np.pi, 400000, endpoint=False))
    to_curve, _ = cKDTree(dense).query(points)
    samples = dense[::200]
    a = points
    b = np.roll(points, -1, axis=0)
    ab = b - a
    length2 = np.maximum((ab ** 2).sum(1), 1e-12)
    t = np.clip(((samples[:, None, :] - a[None]) * ab[None]).sum(2) / length2[None], 0.0, 1.0)
    nearest = a[None] + t[..., None] * ab[None]
    to_contour = np.sqrt(((samples[:, None, :] - nearest) ** 2).sum(2)).min(1)
    return to_curve.mean(), to_curve.max(), to_contour.max()


def contour_distance(p, q):
    """Mean and largest distance of the points of p to the polyline q (closed)."""
    a = q
    b = np.roll(q, -1, axis=0)
    ab = b - a
    length2 = np.maximum((ab ** 2).sum(1), 1e-12)
    t = np.clip(((p[:, None, :] - a[None]) * ab[None]).sum(2) / length2[None], 0.0, 1.0)
    d = np.sqrt(((p[:, None, :] - (a[None] + t[..., None] * ab[None])) ** 2).sum(2)).min(1)
    return d.mean(), d.max()


# --- The two tools ---------------------------------------------------------------

def run_skimage(image, init_rc, repeat=REPEAT, sigma=3.0, **parameters):
    """active_contour on the image smoothed by a Gaussian of sigma pixels (as
    in its documentation); returns the snake as (x, y) and the best time."""
    best = None
    for _ in range(repeat):
        start = time.perf_counter()
        smoothed = gaussian(image, sigma, preserve_range=False)
        snake = active_contour(smoothed, init_rc, **parameters)
        elapsed = time.perf_counter() - start
        best = elapsed if best is None else min(best, elapsed)
    return snake[:, ::-1], best


def read_csv(path):
    return np.loadtxt(path, delimiter=',', skiprows=1, ndmin=2)


def run_edmodel(image_path, arguments, name, repeat=REPEAT):
    """edmodel segment; returns the contour (x, y), the computation's time
    (force field + deformation) warm, as active_contour's is timed (the
    fastest of WARM runs in one process: --repeat), the same in a fresh
    process (the fastest of `repeat` processes, from their stderr), and the
    fastest whole process."""
    output = os.path.join(WORK, name + '.csv')
    command = [EDMODEL, 'segment', '--threads', '1', '--image', image_path, '--output', output] + arguments
    best_compute = best_wall = None
    for _ in range(repeat):
        start = time.perf_counter()
        r = subprocess.run(command, capture_output=True, text=True)
        wall = time.perf_counter() - start
        if r.returncode != 0:
            raise RuntimeError('edmodel failed (%d): %s' % (r.returncode, r.stderr.strip().split('\n')[-1]))
        compute = sum(float(s) for s in re.findall(r'edmodel: (?:force field|deforming): .*\(([0-9.e+-]+) s\)\n',
                                                   r.stderr))
        best_compute = compute if best_compute is None else min(best_compute, compute)
        best_wall = wall if best_wall is None else min(best_wall, wall)
    r = subprocess.run(command + ['--repeat', str(WARM)], capture_output=True, text=True)
    warm = re.search(r'--repeat \d+: force field and deformation in ([0-9.e+-]+) s at best', r.stderr)
    if r.returncode != 0 or not warm:
        raise RuntimeError('edmodel --repeat failed (%d): %s' % (r.returncode, r.stderr.strip().split('\n')[-1]))
    return read_csv(output), float(warm.group(1)), best_compute, best_wall


def circle_rc(cx, cy, radius, n=400):
    """A circle as active_contour's documentation makes it: (row, column),
    n points from 0 to 2 pi (the first repeated at the end)."""
    s = np.linspace(0, 2 * np.pi, n)
    return np.array([cy + radius * np.sin(s), cx + radius * np.cos(s)]).T


def write_csv(path, xy):
    np.savetxt(path, xy, delimiter=',', header='x,y', comments='')


# --- The run --------------------------------------------------------------------

DOCS = dict(alpha=0.015, beta=10, gamma=0.001)  # the astronaut example's parameters


def main():
    print('scikit-image %s, edmodel %s; work directory %s; best of %d runs, edmodel on 1 thread' %
          (skimage.__version__, subprocess.run([EDMODEL, '--version'], capture_output=True, text=True)
           .stdout.split()[1], WORK, REPEAT))
    rows = []
    shapes = [('ellipse (40, 28)', ellipse(63.3, 64.1, 40.0, 28.0), 12.0),
              ('rotated ellipse (40, 28), 0.5 rad', ellipse(63.3, 64.1, 40.0, 28.0, 0.5), 12.0),
              ('star 36 +- 10, 5 arms', star(63.3, 64.1, 36.0, 10.0), 14.0)]
    for label, (curve, inside, extent), inner in shapes:
        image = antialiased((128, 128), inside)
        path = os.path.join(WORK, re.sub('[^a-z]+', '-', label.split(' (')[0].split(' 3')[0]).strip('-') + '.mha')
        write_mha(path, image.astype(np.float32))
        cx, cy = 63.3, 64.1
        outer = extent + 10.0
        init = circle_rc(cx, cy, outer)
        # The runs of the two tools are interleaved: each of the --repeat
        # rounds calls active_contour once per Gaussian and runs each edmodel
        # case once (a fresh process, then one of --repeat WARM runs), and
        # every time is the best over the rounds, so that a slow phase of a
        # shared machine (a neighbour's load, a lower clock) falls on both.
        cases = [('active_contour, docs parameters, Gaussian %g px, circle r %g outside' % (sigma, outer), sigma)
                 for sigma in (3.0, 1.0)]
        cases += [('edmodel segment, ' + how, ['--init-circle', '%g,%g,%g' % (cx, cy, radius)] + arguments)
                  for how, radius, arguments in (('defaults, circle r %g inside' % inner, inner, []),
                                                 ('circle r %g outside, no region force, deflating balloon 0.2 px'
                                                  % outer, outer, ['--region', '0', '--balloon', '-0.2']))]
        results = {}
        for _ in range(REPEAT):
            for tool, how in cases:
                if tool.startswith('active_contour'):
                    snake, seconds = run_skimage(image, init, repeat=1, sigma=how, **DOCS)
                    result = (snake, seconds, None, None)
                else:
                    result = run_edmodel(path, how, 'edmodel-%s-%d' % (os.path.basename(path)[:-4], len(how)),
                                         repeat=1)
                best = results.get(tool)
                results[tool] = result if best is None else (result[0],) + tuple(
                    b if a is None else min(a, b) for a, b in zip(result[1:], best[1:]))
        for tool, _ in cases:
            points, seconds, fresh, wall = results[tool]
            rows.append((label, tool, distances(points, curve), seconds, fresh, wall, len(points)))

    print('\n| Shape | Tool and start | Points | Mean distance to the true boundary (px) | Largest (px) | '
          'Largest gap, boundary to contour (px) | Time: computation, warm (s) | Computation, fresh process (s) | '
          'Whole process (s) |')
    print('|---|---|---|---|---|---|---|---|---|')
    for label, tool, (mean, largest, gap), seconds, fresh, wall, n in rows:
        print('| %s | %s | %d | %.3f | %.3f | %.3f | %.5f | %s | %s |' %
              (label, tool, n, mean, largest, gap, seconds, '%.5f' % fresh if fresh else 'in process',
               '%.3f' % wall if wall else 'in process'))
    # The measure: edmodel's defaults against active_contour with its
    # documented parameters (Gaussian of 3 px), shape by shape.
    print()
    for label in dict.fromkeys(row[0] for row in rows):
        reference = [row for row in rows if row[0] == label and 'Gaussian 3 px' in row[1]][0]
        ours = [row for row in rows if row[0] == label and 'defaults' in row[1]][0]
        print('%s: edmodel\'s defaults %.1f times faster than active_contour (documented parameters) warm, '
              '%.1f times in a fresh process; mean distance %.3f px against %.3f' %
              (label, reference[3] / ours[3], reference[3] / ours[4], ours[2][0], reference[2][0]))

    # The documentation's examples: no known answer; agreement between the tools.
    print('\n| Example | Tool | Points | Time: computation, warm (s) | Time: whole process (s) | '
          'Mean / largest distance of edmodel\'s points to active_contour\'s contour (px) |')
    print('|---|---|---|---|---|---|')
    gray = rgb2gray(data.astronaut())
    path = os.path.join(WORK, 'astronaut.mha')
    write_mha(path, gray.astype(np.float32))
    init = circle_rc(220, 100, 100)
    snake, seconds = run_skimage(gray, init, sigma=3.0, **DOCS)
    write_csv(os.path.join(WORK, 'astronaut-circle.csv'), init[:, ::-1])
    print('| astronaut, circle (220, 100) r 100 | active_contour, docs parameters | %d | %.4f | in process | |' %
          (len(snake), seconds))
    for label, arguments in (('edmodel, defaults, the same circle (the region force estimated inside it: face, hair '
                              'and background)', ['--init-circle', '220,100,100']),
                             ('edmodel, the same circle, no region force, deflating balloon 0.2 px, sigma 3 px',
                              ['--init-circle', '220,100,100', '--region', '0', '--balloon', '-0.2', '--sigma', '3'])):
        try:
            contour, warm, compute, wall = run_edmodel(path, arguments, 'astronaut-' + str(len(arguments)))
            mean, largest = contour_distance(contour, snake)
            print('| astronaut | %s | %d | %.4f (fresh process %.4f) | %.3f | %.2f / %.2f |' %
                  (label, len(contour), warm, compute, wall, mean, largest))
        except RuntimeError as error:
            print('| astronaut | %s | | | | failed: %s |' % (label, error))

    text = data.text()
    path = os.path.join(WORK, 'text.mha')
    write_mha(path, text.astype(np.float32))
    init = np.array([np.linspace(136, 50, 100), np.linspace(5, 424, 100)]).T
    snake, seconds = run_skimage(text, init, sigma=1.0, boundary_condition='fixed', alpha=0.1, beta=1.0, w_line=-5,
                                 w_edge=0, gamma=0.1)
    write_csv(os.path.join(WORK, 'text-line.csv'), init[:, ::-1])
    print('| text, open snake with fixed ends | active_contour, docs parameters | %d | %.4f | in process | |' %
          (len(snake), seconds))
    for label, arguments in (('edmodel, defaults, fixed ends', ['--fixed-boundary']),
                             ('edmodel, fixed ends, sigma 3 px', ['--fixed-boundary', '--sigma', '3'])):
        try:
            contour, warm, compute, wall = run_edmodel(
                path, ['--init-contour', os.path.join(WORK, 'text-line.csv'), '--open'] + arguments,
                'text-' + str(len(arguments)))
            mean, largest = open_distance(contour, snake)
            print('| text | %s | %d | %.4f (fresh process %.4f) | %.3f | %.2f / %.2f |' %
                  (label, len(contour), warm, compute, wall, mean, largest))
        except RuntimeError as error:
            print('| text | %s | | | | failed: %s |' % (label, error))


def open_distance(p, q):
    """Mean and largest distance of the points of p to the open polyline q."""
    a, b = q[:-1], q[1:]
    ab = b - a
    length2 = np.maximum((ab ** 2).sum(1), 1e-12)
    t = np.clip(((p[:, None, :] - a[None]) * ab[None]).sum(2) / length2[None], 0.0, 1.0)
    d = np.sqrt(((p[:, None, :] - (a[None] + t[..., None] * ab[None])) ** 2).sum(2)).min(1)
    return d.mean(), d.max()


if __name__ == '__main__':
    main()
