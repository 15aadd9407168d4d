#!/usr/bin/env python3
"""Every options struct has a validator, and a test calls it (issue #36).

"A validator for every options struct that names field, value and bound,
used by the tools and Python alike": every `struct XxxOptions` of the public
headers (include/robomach/) declares `void Validate() const`, which throws
robomach::OptionError naming the field, its value and the bound
(common/option_checks.h: CheckOptionRange). A struct whose body lacks it is an
error, and so is one that no test under tests/ names next to a Validate()
call (the per-module tests/<module>/options_validate_test.cc).

Usage: check_options_validate.py path/to/source/root
"""
import os
import re
import sys


def struct_bodies(text):
    """(name, body) of every `struct XxxOptions ... { ... };` at any depth."""
    for m in re.finditer(r'\bstruct\s+(\w+Options)\b[^;{]*\{', text):
        depth, i = 1, m.end()
        while i < len(text) and depth:
            depth += {'{': 1, '}': -1}.get(text[i], 0)
            i += 1
        yield m.group(1), text[m.end():i]


def main(root):
    errors = []
    structs = {}
    for dirpath, _, files in os.walk(os.path.join(root, 'include', 'robomach')):
        for f in sorted(files):
            if not f.endswith('.h'):
                continue
            path = os.path.join(dirpath, f)
            text = open(path, encoding='utf-8').read()
            text = re.sub(r'//[^\n]*', '', text)
            for name, body in struct_bodies(text):
                where = os.path.relpath(path, root)
                structs[(where, name)] = body
                if not re.search(r'\bvoid\s+Validate\(\)\s*const\s*;', body):
                    errors.append(f'{where}: struct {name} declares no `void Validate() const;`')
    tests = []
    for dirpath, _, files in os.walk(os.path.join(root, 'tests')):
        for f in files:
            if f.endswith('.cc'):
                tests.append(open(os.path.join(dirpath, f), encoding='utf-8').read())
    for where, name in sorted(structs):
        if not any(re.search(r'\b' + name + r'\b', t) and 'Validate()' in t for t in tests):
            errors.append(f'{where}: no test under tests/ names {name} and calls Validate()')
    for e in errors:
        print(e)
    print(f'{len(structs)} options structs, {len(errors)} problems')
    return 1 if errors else 0


if __name__ == '__main__':
    sys.exit(main(sys.argv[1] if len(sys.argv) > 1 else '.'))
