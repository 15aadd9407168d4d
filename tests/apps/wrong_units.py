#!/usr/bin/env python3
"""Makes a wrong-unit copy of a good input file (issue #22 item 1), the
mistake a user makes, so a test can check that the tool flags it.

  wrong_units.py scale IN OUT COLUMN=FACTOR ...   a CSV column times FACTOR
                                                  (um under _mm: x1000)
  wrong_units.py swap IN OUT COL_A COL_B          two CSV columns' data swapped
                                                  (the header stays)
  wrong_units.py mobility IN OUT                  a UFF58 ASCII receptance's
                                                  values times i*2*pi*f, under
                                                  the receptance header
  wrong_units.py feedrate IN OUT COL BY_COL      COL times BY_COL, per row
                                                  (mm/rev x rpm = mm/min)
  wrong_units.py yaml IN OUT KEY=FACTOR ...       a YAML scalar `KEY: number`
                                                  times FACTOR (every match)
  wrong_units.py nan IN OUT COLUMN ROW TEXT       one CSV cell replaced by TEXT
                                                  (ROW: 0-based data row)
Comment lines (#) are copied as they are.
"""
import cmath
import math
import sys


def split_csv(lines):
    header_at = next(i for i, l in enumerate(lines) if l.strip() and not l.startswith('#'))
    return header_at, lines[header_at].rstrip('\r\n').split(',')


def fmt(v):
    return repr(v) if not float(v).is_integer() else str(v)


def scale(src, dst, specs):
    lines = open(src).read().splitlines()
    h, cols = split_csv(lines)
    factors = {}
    for s in specs:
        name, f = s.split('=')
        factors[cols.index(name)] = float(f)
    out = lines[:h + 1]
    for l in lines[h + 1:]:
        if not l.strip() or l.startswith('#'):
            out.append(l)
            continue
        cells = l.split(',')
        for c, f in factors.items():
            cells[c] = '%.12g' % (float(cells[c]) * f)
        out.append(','.join(cells))
    open(dst, 'w').write('\n'.join(out) + '\n')


def swap(src, dst, a, b):
    lines = open(src).read().splitlines()
    h, cols = split_csv(lines)
    ia, ib = cols.index(a), cols.index(b)
    out = lines[:h + 1]
    for l in lines[h + 1:]:
        if not l.strip() or l.startswith('#'):
            out.append(l)
            continue
        cells = l.split(',')
        cells[ia], cells[ib] = cells[ib], cells[ia]
        out.append(','.join(cells))
    open(dst, 'w').write('\n'.join(out) + '\n')


def feedrate(src, dst, col, by):
    lines = open(src).read().splitlines()
    h, cols = split_csv(lines)
    c, b = cols.index(col), cols.index(by)
    out = lines[:h + 1]
    for l in lines[h + 1:]:
        if l.strip() and not l.startswith('#'):
            cells = l.split(',')
            cells[c] = '%.12g' % (float(cells[c]) * float(cells[b]))
            l = ','.join(cells)
        out.append(l)
    open(dst, 'w').write('\n'.join(out) + '\n')


def yaml_scale(src, dst, specs):
    import re
    text = open(src).read()
    for s in specs:
        key, f = s.split('=')
        pat = re.compile(r'(^\s*' + re.escape(key) + r':\s*)([-+0-9.eE]+)', re.M)
        if not pat.search(text):
            sys.exit('no ' + key + ' in ' + src)
        text = pat.sub(lambda m: m.group(1) + '%.12g' % (float(m.group(2)) * float(f)), text)
    open(dst, 'w').write(text)


def set_cell(src, dst, column, row, text):
    lines = open(src).read().splitlines()
    h, cols = split_csv(lines)
    c = cols.index(column)
    out = lines[:h + 1]
    k = 0
    for l in lines[h + 1:]:
        if l.strip() and not l.startswith('#'):
            if k == int(row):
                cells = l.split(',')
                cells[c] = text
                l = ','.join(cells)
            k += 1
        out.append(l)
    open(dst, 'w').write('\n'.join(out) + '\n')


def mobility(src, dst):
    """Dataset 58 ASCII, even abscissa, complex ordinates (record 7 type 5 or
    6), 4E20.12 data lines: the FRF records (function type 4) are multiplied
    by i*omega; other records (coherence) are copied."""
    lines = open(src).read().splitlines()
    out, i = [], 0
    while i < len(lines):
        if lines[i].strip() == '-1' and i + 1 < len(lines) and lines[i + 1].split()[:1] == ['58']:
            head = lines[i:i + 13]  # delimiter, '58', records 1-11
            out.extend(head)
            function_type = int(head[7][:5])
            r7 = head[8].split()
            n, even, x0, dx = int(r7[1]), int(r7[2]), float(r7[3]), float(r7[4])
            if not even or int(r7[0]) not in (5, 6):
                sys.exit('only even, complex records are handled')
            i += 13
            values = []
            while lines[i].strip() != '-1':
                l = lines[i]
                values += [float(l[k:k + 20]) for k in range(0, len(l.rstrip()), 20)]
                i += 1
            if function_type == 4:
                for p in range(n):
                    z = complex(values[2 * p], values[2 * p + 1]) * 1j * 2 * math.pi * (x0 + p * dx)
                    values[2 * p], values[2 * p + 1] = z.real, z.imag
            for k in range(0, len(values), 4):
                out.append(''.join('%20.11E' % v for v in values[k:k + 4]))
            out.append(lines[i])  # closing -1
            i += 1
        else:
            out.append(lines[i])
            i += 1
    open(dst, 'w').write('\n'.join(out) + '\n')


if __name__ == '__main__':
    cmd, args = sys.argv[1], sys.argv[2:]
    if cmd == 'scale':
        scale(args[0], args[1], args[2:])
    elif cmd == 'swap':
        swap(*args)
    elif cmd == 'mobility':
        mobility(*args)
    elif cmd == 'feedrate':
        feedrate(*args)
    elif cmd == 'yaml':
        yaml_scale(args[0], args[1], args[2:])
    elif cmd == 'nan':
        set_cell(*args)
    else:
        sys.exit(__doc__)
