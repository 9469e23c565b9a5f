#!/usr/bin/env python3
"""The index of the decision records: docs/DECISIONS.md's table, from docs/decisions/D*.md.

Each record is docs/decisions/DNN-short-slug.md whose first line is `# DNN: title` and whose
first line after it that is not blank is `Status: ...`, one of
  accepted [(...)]
  superseded by DNN [(...)]
  partial: what is missing   or   partial (what is missing)

  decisions-index.py            rewrite the table between the index markers of docs/DECISIONS.md
  decisions-index.py --check    exit 1, naming each entry, when the table is not what the
                                records say (missing, extra or mismatched rows) or a record is
                                malformed; change nothing
  decisions-index.py --next     print the next free number (DNN)
  --root DIR                    the repository (default: this script's parent folder's parent)

Python 3 standard library only.
"""

import argparse
import os
import re
import sys

BEGIN = "<!-- decisions-index:begin (scripts/decisions-index.py writes this table) -->"
END = "<!-- decisions-index:end -->"
HEADER = ["| D | title | status |", "|---|---|---|"]
FILE_NAME = re.compile(r"^D(\d{2,})-[A-Za-z0-9][A-Za-z0-9._-]*\.md$")
LOOKS_LIKE_A_RECORD = re.compile(r"^D\d")
TITLE = re.compile(r"^# D(\d{2,}): (\S.*)$")
STATUS = re.compile(r"^Status: (accepted|superseded by D(\d{2,})|partial)(.*)$", re.IGNORECASE)
ROW = re.compile(r"^\| \[D(\d+)\]\(")


class Problems(Exception):
    def __init__(self, lines):
        super().__init__("\n".join(lines))
        self.lines = lines


def read_record(folder, name):
    """(number, title, status) of one record, or a list of what is wrong with it."""
    path = os.path.join(folder, name)
    where = os.path.join("docs/decisions", name)
    with open(path, encoding="utf-8") as f:
        lines = f.read().split("\n")
    wrong = []
    number = int(FILE_NAME.match(name).group(1))
    m = TITLE.match(lines[0]) if lines else None
    if not m:
        return None, ["%s:1: the first line must be '# D%02d: title', not %r" % (where, number, lines[0][:80])]
    if int(m.group(1)) != number:
        wrong.append("%s:1: the title says D%s, the file name D%02d" % (where, m.group(1), number))
    title = m.group(2).strip()
    rest = [(i + 2, l) for i, l in enumerate(lines[1:]) if l.strip()]
    if not rest or not rest[0][1].startswith("Status:"):
        at = rest[0][0] if rest else len(lines)
        wrong.append("%s:%d: no 'Status:' line after the title (accepted, superseded by DNN, or partial: what is missing)"
                     % (where, at))
        return None, wrong
    line_no, line = rest[0]
    s = STATUS.match(line.strip())
    if not s:
        wrong.append("%s:%d: the status must start with 'accepted', 'superseded by DNN' or 'partial', not %r"
                     % (where, line_no, line.strip()[len("Status:"):].strip()[:80]))
        return None, wrong
    if s.group(3).strip(" .") and not s.group(3).startswith((" (", ":", " ")):
        wrong.append("%s:%d: unreadable status %r" % (where, line_no, line.strip()))
    if s.group(1).lower() == "partial" and not s.group(3).strip(" :().-"):
        wrong.append("%s:%d: 'partial' must say what is missing ('partial: ...')" % (where, line_no))
    if wrong:
        return None, wrong
    return (number, title, line.strip()[len("Status:"):].strip(), name, s.group(2)), []


def read_records(root):
    folder = os.path.join(root, "docs", "decisions")
    if not os.path.isdir(folder):
        raise Problems(["no folder %s" % folder])
    records, wrong, seen, numbers = {}, [], {}, set()
    for name in sorted(os.listdir(folder)):
        path = os.path.join(folder, name)
        if not os.path.isfile(path) or not LOOKS_LIKE_A_RECORD.match(name):
            continue
        if not FILE_NAME.match(name):
            wrong.append("docs/decisions/%s: not a record's name (DNN-short-slug.md)" % name)
            continue
        rec, bad = read_record(folder, name)
        wrong.extend(bad)
        numbers.add(int(FILE_NAME.match(name).group(1)))
        if rec is None:
            continue
        if rec[0] in seen:
            wrong.append("docs/decisions/%s: D%02d is also docs/decisions/%s" % (name, rec[0], seen[rec[0]]))
            continue
        seen[rec[0]] = name
        records[rec[0]] = rec
    for number, rec in sorted(records.items()):
        if rec[4] is not None and int(rec[4]) not in records:
            wrong.append("docs/decisions/%s: superseded by D%s, which has no record" % (rec[3], rec[4]))
        elif rec[4] is not None and int(rec[4]) <= number:
            wrong.append("docs/decisions/%s: superseded by D%s, which is not a later record" % (rec[3], rec[4]))
    return records, wrong, numbers


def cell(text):
    return text.replace("|", "\\|")


def rows(records):
    return ["| [D%02d](decisions/%s) | %s | %s |" % (n, r[3], cell(r[1]), cell(r[2]))
            for n, r in sorted(records.items())]


def split_index(text, where):
    """(before, table lines, after) of the index file; the markers must each be there once."""
    lines = text.split("\n")
    if lines.count(BEGIN) != 1 or lines.count(END) != 1 or lines.index(BEGIN) > lines.index(END):
        raise Problems(["%s: needs one line %r and, after it, one line %r" % (where, BEGIN, END)])
    b, e = lines.index(BEGIN), lines.index(END)
    return lines[:b + 1], lines[b + 1:e], lines[e:]


def number_of(row):
    m = ROW.match(row)
    return int(m.group(1)) if m else None


def compare(expected, actual, broken):
    """What differs between the expected and the actual table, one line per entry; the numbers
    of records too malformed to read (reported on their own) are left out."""
    out = []
    body = [l for l in actual if l.strip()]
    if body[:2] != HEADER:
        out.append("the table's header is not %r" % " / ".join(HEADER))
    else:
        body = body[2:]
    want = {number_of(r): r for r in expected}
    have = {}
    for line in body:
        n = number_of(line)
        if n is None:
            out.append("not a row of the index: %r" % line[:80])
        elif n in have:
            out.append("D%02d: listed twice" % n)
        else:
            have[n] = line
    for n in sorted(set(want) | set(have)):
        if n in broken:
            continue
        if n not in have:
            out.append("D%02d: missing from the index (docs/decisions/%s)" % (n, want[n].split("](decisions/")[1].split(")")[0]))
        elif n not in want:
            out.append("D%02d: extra in the index, no record docs/decisions/D%02d-*.md" % (n, n))
        elif have[n] != want[n]:
            out.append("D%02d: mismatched\n    index:   %s\n    records: %s" % (n, have[n], want[n]))
    if not out and not broken and body != expected:
        out.append("the rows are not in the order of their numbers")
    return out


def main(argv):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--check", action="store_true", help="change nothing; exit 1 when the index is stale")
    ap.add_argument("--next", action="store_true", help="print the next free number")
    ap.add_argument("--root", default=os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    args = ap.parse_args(argv)
    index_path = os.path.join(args.root, "docs", "DECISIONS.md")
    try:
        records, wrong, numbers = read_records(args.root)
        if args.next:
            print("D%02d" % (max(numbers, default=0) + 1))
            return 0
        if wrong and not args.check:
            raise Problems(wrong + ["nothing written: mend the records above first"])
        with open(index_path, encoding="utf-8") as f:
            text = f.read()
        before, table, after = split_index(text, "docs/DECISIONS.md")
        expected = rows(records)
        if args.check:
            diff = compare(expected, table, numbers - set(records))
            if wrong or diff:
                raise Problems(wrong + (["docs/DECISIONS.md's index is stale (run scripts/decisions-index.py):"]
                                        + ["  " + d for d in diff] if diff else []))
            print("decisions-index: %d records, the index is current" % len(records))
            return 0
        new = "\n".join(before + HEADER + expected + after)
        if new != text:
            tmp = index_path + ".tmp"
            with open(tmp, "w", encoding="utf-8") as f:
                f.write(new)
            os.replace(tmp, index_path)
            print("decisions-index: wrote %d rows to docs/DECISIONS.md" % len(records))
        else:
            print("decisions-index: %d records, the index was current" % len(records))
        return 0
    except Problems as p:
        print("decisions-index: " + "\n".join(p.lines), file=sys.stderr)
        return 1


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
