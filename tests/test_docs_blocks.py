"""Every Python block of the README, the tutorial and the guides runs.

A page is one session: its blocks run in order in one namespace (``u``,
``np`` and ``orbits`` imported, as the pages assume), in a temporary
folder, so that a block may use what an earlier one made.  Python blocks are
fenced ```` ```python ```` blocks in Markdown and ``.. code-block:: python``,
``.. testsetup::``, ``.. testcleanup::`` and ``.. doctest::`` blocks in
reStructuredText; a doctest block's output is compared as the doctest
module compares it.  Other languages (bash, TOML) are not run.

A comment just before a block (``<!-- docs-test: ... -->`` in Markdown,
``.. docs-test: ...`` in reStructuredText, invisible on the page) says how to
run it when it cannot run as it stands:

* ``skip: REASON``: not run (a cluster's address, an hour of computing); the
  reason must be given;
* ``setup: CODE``: a line run before the block (for names the text says
  where they come from, such as a body set with an Earth);
* ``replace: OLD -> NEW``: the block runs with OLD replaced by NEW (a run
  shortened), and OLD must be in the block.

Any other comment is a note for readers of the source and changes nothing.
"""

import doctest
import pathlib
import re
import textwrap

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[1]
PAGES = [ROOT / "README.md", ROOT / "docs" / "tutorial.rst",
         *sorted((ROOT / "docs" / "guides").glob("*.rst"))]

_RST_BLOCK = re.compile(r"^\.\. (code-block|doctest|testsetup|testcleanup)::\s*(\S*)\s*$")
_MD_FENCE = re.compile(r"^```(\w*)\s*$")
_MD_NOTE = re.compile(r"^<!--\s*docs-test:\s*(.*?)\s*-->\s*$")
_RST_NOTE = re.compile(r"^\.\. docs-test:\s*(.*?)\s*$")


class Block:
    def __init__(self, page, line, kind, code, notes):
        self.page, self.line, self.kind, self.code, self.notes = page, line, kind, code, notes

    def __repr__(self):
        return f"{self.page.name}:{self.line}"


def _markdown_blocks(page, lines):
    notes, i = [], 0
    while i < len(lines):
        note = _MD_NOTE.match(lines[i])
        fence = _MD_FENCE.match(lines[i])
        if note:
            notes.append(note.group(1))
        elif fence:
            lang, start = fence.group(1), i + 1
            i += 1
            while not lines[i].startswith("```"):
                i += 1
            if lang == "python":
                yield Block(page, start, "code", "\n".join(lines[start:i]), notes)
            notes = []
        elif lines[i].strip():
            notes = []
        i += 1


def _rst_blocks(page, lines):
    notes, i = [], 0
    while i < len(lines):
        note = _RST_NOTE.match(lines[i])
        head = _RST_BLOCK.match(lines[i])
        if note:
            notes.append(note.group(1))
        elif head:
            directive, lang = head.groups()
            start = i + 1
            i += 1
            while i < len(lines) and (not lines[i].strip() or lines[i].startswith(" ")):
                i += 1
            body = [ln for ln in lines[start:i] if not ln.lstrip().startswith(":")]
            code = textwrap.dedent("\n".join(body)).strip("\n")
            if directive == "doctest":
                yield Block(page, start, "doctest", code, notes)
            elif directive in ("testsetup", "testcleanup") or lang == "python":
                yield Block(page, start, "code", code, notes)
            notes = []
            continue
        elif lines[i].strip():
            notes = []
        i += 1


def blocks(page):
    lines = page.read_text().splitlines()
    maker = _markdown_blocks if page.suffix == ".md" else _rst_blocks
    return list(maker(page, lines))


def _prepared(block):
    """The block's code as it runs, and whether it runs (with the reason if not)."""
    code, setup = block.code, []
    for note in block.notes:
        key, _, rest = note.partition(":")
        key, rest = key.strip(), rest.strip()
        if key == "skip":
            assert rest, f"{block}: a skipped block needs its reason"
            return None, rest
        if key == "setup":
            setup.append(rest)
        elif key == "replace":
            old, sep, new = rest.partition(" -> ")
            assert sep and old in code, f"{block}: {old!r} is not in the block"
            code = code.replace(old, new)
    return "\n".join(setup + [code]), None


def _run(block, namespace):
    code, skipped = _prepared(block)
    if code is None:
        return skipped
    if block.kind == "code":
        exec(compile(code, f"{block}", "exec"), namespace)
        return None
    parser = doctest.DocTestParser()
    test = parser.get_doctest(code, namespace, str(block), str(block.page), block.line)
    runner = doctest.DocTestRunner(optionflags=doctest.ELLIPSIS | doctest.IGNORE_EXCEPTION_DETAIL
                                   | doctest.DONT_ACCEPT_TRUE_FOR_1)
    out = []
    runner.run(test, out=out.append, clear_globs=False)
    namespace.update(test.globs)   # the test ran in a copy of the page's namespace
    assert runner.failures == 0, "".join(out)
    return None


@pytest.mark.parametrize("page", PAGES, ids=lambda p: p.name)
def test_page_blocks_run(page, tmp_path, monkeypatch):
    found = blocks(page)
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("MPLBACKEND", "Agg")
    namespace = {"__name__": "__docs__"}
    exec("import astropy.units as u\nimport numpy as np\nimport orbits", namespace)
    skipped = []
    for block in found:
        reason = _run(block, namespace)
        if reason:
            skipped.append(f"{block}: {reason}")
    # a page of Python examples all skipped would test nothing
    assert len(skipped) < len(found) or not found, skipped


def test_the_parser_finds_the_blocks():
    # the README's first script and a guide's doctest block, found where they are
    readme = blocks(ROOT / "README.md")
    assert any("orbits.BodySet()" in b.code for b in readme)
    units = blocks(ROOT / "docs" / "guides" / "units.rst")
    assert any(b.kind == "doctest" for b in units)


def test_a_failing_block_fails(tmp_path):
    page = tmp_path / "page.md"
    page.write_text("```python\nmasses\n```\n")
    (block,) = blocks(page)
    with pytest.raises(NameError):
        _run(block, {})


def test_a_doctest_block_compares_its_output(tmp_path):
    page = tmp_path / "page.rst"
    page.write_text(".. doctest::\n\n   >>> 1 + 1\n   3\n")
    (block,) = blocks(page)
    with pytest.raises(AssertionError, match="Expected"):
        _run(block, {})


def test_notes_skip_and_replace(tmp_path):
    page = tmp_path / "page.md"
    page.write_text("<!-- docs-test: skip: needs a cluster -->\n```python\nboom\n```\n\n"
                    "<!-- docs-test: replace: 10 -> 2 -->\n```python\nx = 10\n```\n")
    first, second = blocks(page)
    ns = {}
    assert _run(first, ns) == "needs a cluster"
    _run(second, ns)
    assert ns["x"] == 2
