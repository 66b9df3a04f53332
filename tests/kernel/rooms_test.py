#!/usr/bin/env python3
"""The kernel's rooms keep their shape by themselves (kernel/src/README.md).

Reads the README's table (which room may include which) and its list of room
tests, then checks every #include "room/..." in the tree:
  - a file of kernel/src/ROOM includes only its own room and the rooms the
    table lets it;
  - nothing outside kernel/src includes a room's header, except the listed
    room tests; and no CMakeLists outside kernel/ puts kernel/src on an
    include path;
  - no public header (kernel/include) includes a room's header.

Usage: rooms_test.py SOURCE_DIR   check the tree
       rooms_test.py --self-test  show that a forbidden include is caught
                                  (on a small tree made in a temporary folder)
"""
import os
import re
import sys
import tempfile

INCLUDE = re.compile(r'^\s*#\s*include\s+"([^"]+)"', re.M)
SOURCES = ('.cpp', '.hpp', '.h', '.cc', '.inl')


def read_rules(root):
    """{room: set of rooms it may include} and the room tests, from kernel/src/README.md."""
    text = open(os.path.join(root, 'kernel/src/README.md'), encoding='utf-8').read()
    rooms = {}
    for line in text.splitlines():
        m = re.match(r'^\|\s*`(\w+)/`\s*\|[^|]*\|([^|]*)\|', line)
        if not m:
            continue
        room, allowed = m.group(1), m.group(2)
        rooms[room] = set(re.findall(r'`(\w+)/`', allowed))
        if 'every room' in allowed:
            rooms[room] = {'*'}
    if not rooms:
        raise SystemExit('FAIL: no room table found in kernel/src/README.md')
    m = re.search(r'Room tests:(.*?)(?:\n\n|$)', text, re.S)
    tests = re.findall(r'`([^`]+)`', m.group(1)) if m else []
    return rooms, tests


def source_files(folder):
    for dirpath, dirnames, filenames in os.walk(folder):
        dirnames[:] = [d for d in dirnames if not d.startswith('.') and d not in ('node_modules',)]
        for f in filenames:
            if f.endswith(SOURCES):
                yield os.path.join(dirpath, f)


def room_includes(path, rooms):
    """(line, room, header) for each #include "room/header" of `path`."""
    text = open(path, encoding='utf-8', errors='replace').read()
    for m in INCLUDE.finditer(text):
        target = m.group(1)
        first = target.split('/')[0]
        if '/' in target and first in rooms:
            yield text.count('\n', 0, m.start()) + 1, first, target


def check(root):
    rooms, tests = read_rules(root)
    problems = []
    src = os.path.join(root, 'kernel/src')
    for room in sorted(rooms):
        for path in source_files(os.path.join(src, room)):
            for line, other, target in room_includes(path, rooms):
                if other == room or '*' in rooms[room] or other in rooms[room]:
                    continue
                allowed = ', '.join(sorted(r + '/' for r in rooms[room])) or 'no other room'
                problems.append(f'{os.path.relpath(path, root)}:{line}: room {room}/ includes "{target}", but '
                                f'kernel/src/README.md lets {room}/ include {allowed}')
    # Outside kernel/src: the front door only (the room tests excepted).
    def is_room_test(rel):
        return any(rel == t or (t.endswith('/') and rel.startswith(t)) for t in tests)

    outside = ['kernel/cli', 'kernel/include', 'python', 'viewer', 'plugins', 'libs', 'gl', 'tests']
    for top in outside:
        folder = os.path.join(root, top)
        if not os.path.isdir(folder):
            continue
        for path in source_files(folder):
            rel = os.path.relpath(path, root)
            if is_room_test(rel):
                continue
            for line, _, target in room_includes(path, rooms):
                problems.append(f'{rel}:{line}: includes the kernel\'s private "{target}"; go through '
                                f'<orogen/session.hpp> (or, for a room\'s unit test, list it under "Room tests" in '
                                f'kernel/src/README.md)')
    for dirpath, dirnames, filenames in os.walk(root):
        dirnames[:] = [d for d in dirnames
                       if not d.startswith(('.', 'build')) and d != 'node_modules']
        rel = os.path.relpath(dirpath, root)
        if rel == 'kernel' or rel.startswith('kernel' + os.sep) or 'CMakeLists.txt' not in filenames:
            continue
        cm = open(os.path.join(dirpath, 'CMakeLists.txt'), encoding='utf-8').read()
        for i, l in enumerate(cm.splitlines(), 1):
            if re.search(r'kernel/src\b', l) and 'include' in l.lower() and not l.lstrip().startswith('#'):
                if rel.startswith('tests'):
                    continue  # room tests reach the rooms; which files may is checked above
                problems.append(f'{os.path.join(rel, "CMakeLists.txt")}:{i}: puts kernel/src on an include path')
    return problems


def self_test():
    """A tree with one include of each forbidden kind: every one must be reported."""
    with tempfile.TemporaryDirectory() as root:
        def write(rel, text):
            path = os.path.join(root, rel)
            os.makedirs(os.path.dirname(path), exist_ok=True)
            open(path, 'w', encoding='utf-8').write(text)
        write('kernel/src/README.md',
              '| room | holds | may include |\n|---|---|---|\n| `io/` | files | nothing else |\n'
              '| `spec/` | the language | `io/` |\n| `run/` | the runner | every room |\n\n'
              'Room tests: `tests/kernel/spec_test.cpp`.\n')
        write('kernel/src/io/io.cpp', '#include "io/io.hpp"\n#include "spec/plan.hpp"\n')  # io -> spec: wrong
        write('kernel/src/spec/checker.cpp', '#include "io/outputs.hpp"\n#include "run/runner.hpp"\n')  # -> run: wrong
        write('kernel/src/run/runner.cpp', '#include "spec/plan.hpp"\n#include "io/io.hpp"\n')  # fine
        write('kernel/cli/main.cpp', '#include <orogen/session.hpp>\n#include "run/loader.hpp"\n')  # wrong
        write('tests/kernel/spec_test.cpp', '#include "spec/spec.hpp"\n')  # a room test: fine
        write('tests/kernel/other_test.cpp', '#include "spec/spec.hpp"\n')  # not listed: wrong
        write('python/CMakeLists.txt', 'target_include_directories(m PRIVATE ${PROJECT_SOURCE_DIR}/kernel/src)\n')
        problems = check(root)
        want = ['kernel/src/io/io.cpp:2', 'kernel/src/spec/checker.cpp:2', 'kernel/cli/main.cpp:2',
                'tests/kernel/other_test.cpp:1', 'python/CMakeLists.txt:1']
        missed = [w for w in want if not any(p.startswith(w + ':') for p in problems)]
        extra = [p for p in problems if not any(p.startswith(w + ':') for w in want)]
        if missed or extra:
            print('FAIL: the rule checker missed', missed, 'and reported wrongly', extra)
            return 1
        print(f'ok: all {len(want)} forbidden includes of the sample tree were reported, and nothing else')
        return 0


def main():
    if len(sys.argv) == 2 and sys.argv[1] == '--self-test':
        return self_test()
    if len(sys.argv) != 2:
        print(__doc__)
        return 2
    problems = check(sys.argv[1])
    for p in problems:
        print(p)
    if problems:
        print(f'FAIL: {len(problems)} include(s) against kernel/src/README.md')
        return 1
    print('ok: every include follows kernel/src/README.md')
    return 0


if __name__ == '__main__':
    sys.exit(main())
