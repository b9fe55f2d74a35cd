#!/usr/bin/env python3
"""Doxygen INPUT_FILTER for edgefem's public headers (docs/Doxyfile).

The headers are commented with plain // comments. This turns them into
Doxygen documentation without touching the sources:
  * the comment block that opens a file becomes its @file description;
  * a // block directly above a declaration (no blank line between, outside
    function bodies) becomes its /// documentation;
  * a trailing // comment after a member or enumerator becomes ///<;
and escapes the characters Doxygen would read as commands or HTML.
Files that already use Doxygen comments (/** or ///) pass unchanged. Line
numbers are preserved, so warnings point at the right lines.
"""
import re
import sys

SCOPE_OPEN = re.compile(r'^\s*(template\s*<[^>]*>\s*)?(namespace\b|(class|struct|union|enum)\b[^;(]*$|enum\s+class\b|extern\s+"C")')


def escape(text):
    """Escapes Doxygen-special characters outside `code spans`."""
    parts = re.split(r'(`[^`]*`)', text)
    out = []
    for i, p in enumerate(parts):
        if i % 2 == 1:
            out.append(p)
            continue
        p = p.replace('\\', '\\\\').replace('@', '\\@').replace('<', '\\<').replace('>', '\\>')
        p = p.replace('&', '\\&').replace('#', '\\#').replace('%', '\\%').replace('$', '\\$')
        out.append(p)
    return ''.join(out)


def strip_strings(code):
    return re.sub(r'"(\\.|[^"\\])*"|\'(\\.|[^\'\\])*\'', '""', code)


def main(path):
    with open(path, encoding='utf-8') as f:
        lines = f.read().split('\n')
    text = '\n'.join(lines)
    if '/**' in text or re.search(r'^\s*///', text, re.M):
        sys.stdout.write(text)
        return
    out = list(lines)
    n = len(lines)
    # The opening comment block -> @file.
    i = 0
    while i < n and lines[i].strip().startswith('//'):
        i += 1
    if i > 0:
        for k in range(i):
            body = escape(lines[k].strip()[2:].strip())
            out[k] = ('/** ' if k == 0 else ' * ') + body + (' @file */' if k == i - 1 else '')
    # Scope tracking: a stack of 'scope' / 'body' braces.
    stack = []
    pending = []  # indices of the current // block
    for k in range(i, n):
        line = lines[k]
        s = line.strip()
        if s.startswith('//'):
            pending.append(k)
            continue
        code = line.split('//', 1)[0] if '//' in strip_strings(line) else line
        in_scope = all(t == 'scope' for t in stack)
        if pending:
            if in_scope and s and not s.startswith('#') and not s.startswith('}'):
                for p in pending:
                    c = lines[p]
                    indent = c[:len(c) - len(c.lstrip())]
                    out[p] = indent + '/// ' + escape(c.strip()[2:].strip())
            pending = []
        # trailing comment on a member / enumerator / declaration
        m = re.match(r'^(.*?[;,{A-Za-z0-9_)\]])(\s*)//(.*)$', line)
        if in_scope and m and '//' in strip_strings(line) and not s.startswith('#'):
            codepart = m.group(1).rstrip()
            if codepart.endswith((';', ',')) or re.match(r'^\s*[A-Za-z_]\w*\s*(=\s*[^,]+)?$', codepart):
                out[k] = m.group(1) + m.group(2) + '///< ' + escape(m.group(3).strip())
        # braces
        c = strip_strings(code)
        opens_scope = bool(SCOPE_OPEN.match(c)) or (bool(re.match(r'^\s*\{', c)) and k > 0 and SCOPE_OPEN.match(strip_strings(lines[k - 1].split('//')[0])))
        for ch in c:
            if ch == '{':
                stack.append('scope' if opens_scope else 'body')
                opens_scope = False
            elif ch == '}':
                if stack:
                    stack.pop()
    sys.stdout.write('\n'.join(out))


if __name__ == '__main__':
    main(sys.argv[1])
