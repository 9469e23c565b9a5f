"""CTest cellmodel.copies: the two hand-written copies of the nominal forward kinematics
outside C++ agree with the cell model (docs/DECISIONS.md D24).

  check_copies.py <arflex-cellmodel> <scripts/run-cell.sh> <tests/.../NominalArm.java>

- the `fk(q)` of run-cell.sh's summary (Python) is taken from the script and run at a few
  poses against `arflex-cellmodel fk`;
- the chain constants of NominalArm.java (OFFSETS, AXES, TCP) are compared with
  `arflex-cellmodel chain`.
"""
import math
import re
import subprocess
import sys

cli, script, java = sys.argv[1:4]
failures = []

# --- run-cell.sh: the Python fk(q), run as written --------------------------------------
text = open(script).read()
m = re.search(r"^def fk\(q\):\n(?:(?:    .*)?\n)+", text, re.M)
if not m:
    sys.exit("FAIL: no 'def fk(q):' in %s" % script)
scope = {"math": math}
exec(m.group(0), scope)
poses = [(0, 0, 0, 0, 0, 0), (0.3, 0.2, 0.5, -0.4, 0.7, 0.1), (0.1, 0.45, 0.35, 0.2, 0.7, 0.3),
         (-1.2, -0.5, 1.1, 2.0, -1.0, 3.0), (0.2, 0.5, 0.3, 0.1, 0.8, -0.2)]
for q in poses:
    out = subprocess.run([cli, "fk"] + ["%.17g" % v for v in q], check=True,
                         capture_output=True, text=True).stdout.split()
    want = [float(v) for v in out[:3]]
    got = scope["fk"](q)
    if math.dist(want, got) > 1e-12:
        failures.append("run-cell.sh fk%s = %s, cell model %s" % (q, got, want))

# --- NominalArm.java: the chain constants -------------------------------------------------
src = open(java).read()
def numbers(s):
    return [float(v) for v in re.findall(r"-?\d+(?:\.\d+)?(?:[eE]-?\d+)?", s)]
offs = re.search(r"OFFSETS\s*=\s*\{(.*?)\};", src, re.S)
axes = re.search(r"AXES\s*=\s*\{(.*?)\};", src, re.S)
tcp = re.search(r"TCP\s*=\s*\{(.*?)\};", src, re.S)
if not (offs and axes and tcp):
    sys.exit("FAIL: OFFSETS/AXES/TCP not found in %s" % java)
j_offs = numbers(offs.group(1))
j_axes = re.findall(r"'([xyz])'", axes.group(1))
j_tcp = numbers(tcp.group(1))
chain = subprocess.run([cli, "chain"], check=True, capture_output=True, text=True).stdout
m_offs, m_axes, m_tcp = [], [], []
for line in chain.splitlines():
    f = line.split()
    if f[0] == "joint":
        m_axes.append(f[3])
        m_offs += [float(v) for v in f[5:8]]
    elif f[0] == "tcp":
        m_tcp = [float(v) for v in f[1:4]]
if j_axes != m_axes:
    failures.append("NominalArm.java AXES %s, cell model %s" % (j_axes, m_axes))
if len(j_offs) != len(m_offs) or max(abs(a - b) for a, b in zip(j_offs, m_offs)) > 1e-15:
    failures.append("NominalArm.java OFFSETS %s, cell model %s" % (j_offs, m_offs))
if len(j_tcp) != 3 or max(abs(a - b) for a, b in zip(j_tcp, m_tcp)) > 1e-15:
    failures.append("NominalArm.java TCP %s, cell model %s" % (j_tcp, m_tcp))

for f in failures:
    print("FAIL " + f)
if failures:
    sys.exit(1)
print("ok: run-cell.sh fk at %d poses and NominalArm.java's chain equal the cell model" % len(poses))
