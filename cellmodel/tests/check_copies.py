"""CTest cellmodel.copies: the hand-written copies of the nominal forward kinematics outside
C++ agree with the cell model (docs/DECISIONS.md D24, D31).

  check_copies.py <arflex-cellmodel> <NominalArm.java>...

The chain constants (OFFSETS, AXES, TCP) of each NominalArm.java (the DRCR's, for
`arflex:summary` and the integration tests' TRUE-error reference) are compared with
`arflex-cellmodel chain`. The DRCR's copy is also run, by its unit test CellSummaryTest, at
five poses against values `arflex-cellmodel fk` printed.
"""
import re
import subprocess
import sys

cli, javas = sys.argv[1], sys.argv[2:]
if not javas:
    sys.exit("usage: check_copies.py <arflex-cellmodel> <NominalArm.java>...")

chain = subprocess.run([cli, "chain"], check=True, capture_output=True, text=True).stdout
m_offs, m_axes, m_tcp = [], [], []
for line in chain.splitlines():
    f = line.split()
    if f[0] == "joint":
        m_axes.append(f[3])
        m_offs += [float(v) for v in f[5:8]]
    elif f[0] == "tcp":
        m_tcp = [float(v) for v in f[1:4]]


def numbers(s):
    return [float(v) for v in re.findall(r"-?\d+(?:\.\d+)?(?:[eE]-?\d+)?", s)]


failures = []
for java in javas:
    src = open(java).read()
    offs = re.search(r"OFFSETS\s*=\s*\{(.*?)\};", src, re.S)
    axes = re.search(r"AXES\s*=\s*\{(.*?)\};", src, re.S)
    tcp = re.search(r"TCP\s*=\s*\{(.*?)\};", src, re.S)
    if not (offs and axes and tcp):
        sys.exit("FAIL: OFFSETS/AXES/TCP not found in %s" % java)
    j_offs = numbers(offs.group(1))
    j_axes = re.findall(r"'([xyz])'", axes.group(1))
    j_tcp = numbers(tcp.group(1))
    if j_axes != m_axes:
        failures.append("%s AXES %s, cell model %s" % (java, j_axes, m_axes))
    if len(j_offs) != len(m_offs) or max(abs(a - b) for a, b in zip(j_offs, m_offs)) > 1e-15:
        failures.append("%s OFFSETS %s, cell model %s" % (java, j_offs, m_offs))
    if len(j_tcp) != 3 or max(abs(a - b) for a, b in zip(j_tcp, m_tcp)) > 1e-15:
        failures.append("%s TCP %s, cell model %s" % (java, j_tcp, m_tcp))

for f in failures:
    print("FAIL " + f)
if failures:
    sys.exit(1)
print("ok: the chains of %d NominalArm.java copies equal the cell model" % len(javas))
