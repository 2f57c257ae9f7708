#!/usr/bin/env python3
"""Checks primo's documentation; exits 1 naming every problem it finds.

- Links: every relative link and `#anchor` in README.md, ARCHITECTURE.md,
  CHANGELOG.md, python/README.md, bench/results/*.md and the book
  (docs/src) resolves: the file or directory exists, the anchor is a
  heading of the target Markdown file (GitHub's and mdBook's ids) or an
  `id` of the target HTML file (for the book's pages, also of the page
  `mdbook build docs` made, when docs/book exists). Links under `target/` (rustdoc, built by
  `cargo doc --workspace --no-deps`) are looked up in cargo's target
  directory. Every page of docs/src is listed in SUMMARY.md.
- Command lines: every `primo ...` command in a `sh` block, and every
  synopsis line starting with `primo` in a `text` block, names real
  subcommands and only flags their `--help` lists (the binary given by
  --primo). `cargo run ... --bin primo -- ARGS` counts as `primo ARGS`.
- Blocks: `python` blocks are compiled, and run (each in a scratch
  directory, with --python, the primo binary's directory first on PATH)
  unless an HTML comment `<!-- check: compile-only -->` precedes them;
  `toml` blocks parse; `json` blocks without `...` parse (whole, or line
  by line). `sh` blocks preceded by `<!-- check: run -->` are run, those
  of one file in order, in one scratch directory, with bash -euo pipefail.

Python 3.11 standard library only. Usage, from anywhere:
    python3 docs/check.py --primo target/debug/primo [--python PY]
"""

import argparse
import json
import os
import re
import shlex
import subprocess
import sys
import tempfile
import time
import tomllib
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
FENCE = re.compile(r"^(\s*)(```+|~~~+)\s*([^\s`]*)")
HEADING = re.compile(r"^(#{1,6})\s+(.*?)\s*#*\s*$")
LINK = re.compile(r"!?\[(?:[^\[\]]|\[[^\]]*\])*\]\(\s*<?([^)\s>]*)>?(?:\s+\"[^\"]*\")?\s*\)")
REFDEF = re.compile(r"^\s{0,3}\[[^\]]+\]:\s*<?(\S+?)>?(?:\s+\"[^\"]*\")?\s*$")
MARKER = re.compile(r"<!--\s*check:\s*([\w-]+)[^>]*-->")
CODE_SPAN = re.compile(r"(`+)(.+?)\1")
FLAG = re.compile(r"(?<![\w-])--[a-z][a-z0-9-]*")

problems: list[str] = []
runs: list[tuple[float, str]] = []  # seconds, what ran


def problem(where: str, what: str) -> None:
    problems.append(f"{where}: {what}")


def rel(path: Path) -> str:
    try:
        return str(path.relative_to(ROOT))
    except ValueError:
        return str(path)


class Doc:
    """A Markdown file: its prose lines, code blocks, links and anchors."""

    def __init__(self, path: Path):
        self.path = path
        self.blocks: list[tuple[int, str, str, str | None]] = []  # line, lang, text, marker
        self.links: list[tuple[int, str]] = []
        self.anchors: set[str] = set()
        seen: dict[str, int] = {}
        lines = path.read_text(encoding="utf-8").split("\n")
        fence, lang, start, body, marker = None, "", 0, [], None
        for n, line in enumerate(lines, 1):
            if fence:
                if line.strip().startswith(fence) and line.strip().strip(fence[0]) == "":
                    self.blocks.append((start, lang, "\n".join(body), marker))
                    fence, marker = None, None
                else:
                    body.append(line)
                continue
            m = FENCE.match(line)
            if m:
                fence, lang, start, body = m.group(2), m.group(3).split(",")[0].lower(), n, []
                continue
            mm = MARKER.search(line)
            if mm:
                marker = mm.group(1)
            elif line.strip():
                marker = None
            h = HEADING.match(line)
            if h:
                slug = slugify(h.group(2))
                count = seen.get(slug, 0)
                seen[slug] = count + 1
                self.anchors.add(slug if count == 0 else f"{slug}-{count}")
            prose = CODE_SPAN.sub("", line)
            for m in LINK.finditer(prose):
                self.links.append((n, m.group(1)))
            m = REFDEF.match(prose)
            if m:
                self.links.append((n, m.group(1)))
        if fence:
            problem(f"{rel(path)}:{start}", "code block never closed")


def slugify(heading: str) -> str:
    """A heading's id, as GitHub and mdBook make it (for the headings used here)."""
    text = re.sub(r"!?\[([^\]]*)\]\([^)]*\)", r"\1", heading)
    text = re.sub(r"<[^>]+>", "", text).replace("`", "").replace("*", "")
    out = []
    for ch in text.strip().lower():
        if ch.isalnum() or ch in "-_":
            out.append(ch)
        elif ch.isspace():
            out.append("-")
    return "".join(out)


def target_dir() -> Path:
    if os.environ.get("CARGO_TARGET_DIR"):
        return Path(os.environ["CARGO_TARGET_DIR"]).resolve()
    try:
        meta = subprocess.run(
            ["cargo", "metadata", "--format-version", "1", "--no-deps"],
            cwd=ROOT, check=True, capture_output=True, text=True,
        )
        return Path(json.loads(meta.stdout)["target_directory"])
    except (OSError, subprocess.CalledProcessError):
        return ROOT / "target"


DOCS: dict[Path, Doc] = {}
HTML_IDS: dict[Path, set[str]] = {}
BOOK_SRC = ROOT / "docs" / "src"
BOOK_OUT = ROOT / "docs" / "book"  # mdbook build docs


def html_ids(path: Path) -> set[str]:
    if path not in HTML_IDS:
        HTML_IDS[path] = set(re.findall(r'\bid="([^"]+)"', path.read_text(encoding="utf-8")))
    return HTML_IDS[path]


def doc(path: Path) -> Doc:
    if path not in DOCS:
        DOCS[path] = Doc(path)
    return DOCS[path]


def check_links(d: Doc, target: Path) -> None:
    for n, link in d.links:
        where = f"{rel(d.path)}:{n}"
        if not link or re.match(r"^[a-z][a-z0-9+.-]*:", link):
            if not link:
                problem(where, "empty link")
            continue  # http:, https:, mailto: are not checked
        path, _, anchor = link.partition("#")
        dest = (d.path.parent / path).resolve() if path else d.path
        try:
            inside = dest.relative_to(ROOT)
        except ValueError:
            problem(where, f"link `{link}` leaves the repository")
            continue
        if inside.parts and inside.parts[0] == "target":
            dest = target.joinpath(*inside.parts[1:])
        if not dest.exists():
            hint = " (run `cargo doc --workspace --no-deps` first)" if "doc" in inside.parts[:2] else ""
            problem(where, f"link `{link}`: no such file {rel(dest)}{hint}")
            continue
        if not anchor:
            continue
        if dest.suffix == ".md":
            if anchor not in doc(dest).anchors:
                problem(where, f"link `{link}`: no heading `#{anchor}` in {rel(dest)}")
            rendered = BOOK_OUT / dest.relative_to(BOOK_SRC).with_suffix(".html") if BOOK_SRC in dest.parents else None
            if rendered and rendered.exists() and anchor not in html_ids(rendered):
                problem(where, f"link `{link}`: mdBook made no id `{anchor}` in {rel(rendered)}")
        elif dest.suffix == ".html":
            if anchor not in html_ids(dest):
                problem(where, f"link `{link}`: no id `{anchor}` in {rel(dest)}")
        else:
            problem(where, f"link `{link}`: an anchor into a file that has none")


def check_summary(book: Path) -> None:
    summary = doc(book / "SUMMARY.md")
    listed = {(book / link.partition("#")[0]).resolve() for _, link in summary.links if link}
    for page in sorted(book.rglob("*.md")):
        if page.name != "SUMMARY.md" and page.resolve() not in listed:
            problem(rel(page), "not listed in docs/src/SUMMARY.md (mdBook would not build it)")


class Help:
    """`primo ... --help`, parsed into its subcommands and flags."""

    cache: dict[tuple[str, ...], tuple[set[str], set[str]] | None] = {}

    def __init__(self, primo: str):
        self.primo = primo

    def of(self, path: tuple[str, ...]) -> tuple[set[str], set[str]] | None:
        if path not in self.cache:
            run = subprocess.run([self.primo, *path, "--help"], capture_output=True, text=True)
            if run.returncode != 0:
                self.cache[path] = None
            else:
                commands, flags, section = set(), {"--help"}, None
                for line in run.stdout.splitlines():
                    if re.match(r"^\S.*:$", line):
                        section = line[:-1]
                    elif section == "Commands":
                        m = re.match(r"^\s{2}(\S+)", line)
                        if m and m.group(1) != "help":
                            commands.add(m.group(1))
                    elif section == "Options":
                        m = re.match(r"^\s+(?:-\w, )?(--[\w-]+)", line)
                        if m:
                            flags.add(m.group(1))
                if "-V, --version" in run.stdout:
                    flags.add("--version")
                self.cache[path] = (commands, flags)
        return self.cache[path]

    def check(self, where: str, words: list[str], flags: list[str]) -> None:
        """`words`: the arguments after `primo`; `flags`: the flags used."""
        said = next((w for w in words if not w.isidentifier() or w.endswith(":")), "")
        if words and (words[0].startswith("<") or said.endswith(":")):
            # A placeholder (`primo <COMMAND>`), or a line primo printed
            # (`primo pour: ...`, `primo robot play: ...`).
            return
        paths = [()]
        for word in words:
            if word.startswith("-"):
                break
            level = self.of(paths[0])
            if level is None or not level[0]:
                break  # no subcommands here: the rest are arguments
            names = word.split("|")
            unknown = [w for w in names if w not in level[0]]
            if unknown:
                shown = " ".join(("primo",) + paths[0])
                problem(where, f"`{shown}` has no subcommand `{unknown[0]}`")
                return
            paths = [p + (w,) for p in paths for w in names]
        for path in paths:
            shown = " ".join(("primo",) + path)
            level = self.of(path)
            if level is None:
                problem(where, f"`{shown} --help` fails")
                continue
            if level[0] and not set(flags) <= {"--help", "--version"}:
                problem(where, f"`{shown}` needs a subcommand: {', '.join(sorted(level[0]))}")
                continue
            for flag in flags:
                if flag not in level[1]:
                    problem(where, f"`{shown}` has no flag `{flag}`")


def commands_in_sh(text: str) -> list[list[str]]:
    """Each simple command of a shell block, as words (heredoc bodies skipped)."""
    out, lines, i = [], text.split("\n"), 0
    joined = []
    while i < len(lines):
        line = lines[i]
        while line.endswith("\\") and i + 1 < len(lines):
            i += 1
            line = line[:-1] + " " + lines[i]
        joined.append(line)
        m = re.search(r"<<-?\s*['\"]?(\w+)['\"]?", line)
        if m:
            end = m.group(1)
            i += 1
            while i < len(lines) and lines[i].strip() != end:
                i += 1
        i += 1
    for line in joined:
        line = re.sub(r"<<-?\s*['\"]?\w+['\"]?", "", line)
        try:
            lex = shlex.shlex(line, posix=True, punctuation_chars=True)
            lex.whitespace_split = True
            lex.commenters = "#"
            tokens = list(lex)
        except ValueError:
            continue
        words: list[str] = []
        for tok in tokens + [";"]:
            if tok and set(tok) <= set(";&|()<>"):
                if words:
                    out.append(words)
                words = []
                if tok in ("<", ">", ">>", "2>", "&>"):
                    words = ["<redirect>"]
            elif words == ["<redirect>"]:
                words = []
            else:
                words.append(tok)
    return out


def primo_args(words: list[str]) -> list[str] | None:
    """The arguments of a command that runs primo, or None."""
    while words and (re.match(r"^\w+=", words[0]) or words[0] in ("sudo", "time", "exec", "command")):
        words = words[1:]
    if not words:
        return None
    if Path(words[0]).name == "primo":
        return words[1:]
    if words[0] == "cargo" and "run" in words and "--bin" in words:
        at = words.index("--bin")
        if at + 1 < len(words) and words[at + 1] == "primo":
            return words[words.index("--") + 1:] if "--" in words else []
    return None


def check_commands(d: Doc, help: Help) -> None:
    for start, lang, text, _ in d.blocks:
        where = f"{rel(d.path)}:{start}"
        if lang in ("sh", "bash", "shell", "console"):
            for words in commands_in_sh(text):
                args = primo_args(words)
                if args is not None:
                    flags = [w.split("=")[0] for w in args if w.startswith("--") and w != "--"]
                    help.check(where, args, flags)
        elif lang == "text":
            synopses: list[str] = []
            for line in text.split("\n"):
                if line.startswith("primo "):
                    synopses.append(line)
                elif synopses and line.startswith(" ") and line.strip().startswith(("[", "--")):
                    synopses[-1] += " " + line
            for line in synopses:
                line = line.split(" #")[0]
                words = line.split()[1:]
                help.check(where, words, FLAG.findall(line))


def check_blocks(d: Doc, python: str | None, bindir: str | None) -> None:
    scripts = []
    for start, lang, text, marker in d.blocks:
        where = f"{rel(d.path)}:{start}"
        if lang == "python":
            try:
                compile(text, where, "exec")
            except SyntaxError as e:
                problem(where, f"Python does not compile: {e}")
                continue
            if python and marker != "compile-only":
                run_in_scratch(where, [python, "-c", text], bindir)
        elif lang == "toml":
            try:
                tomllib.loads(text)
            except tomllib.TOMLDecodeError as e:
                problem(where, f"TOML does not parse: {e}")
        elif lang == "json" and "..." not in text:
            try:
                json.loads(text)
            except json.JSONDecodeError:
                for line in filter(str.strip, text.split("\n")):
                    try:
                        json.loads(line)
                    except json.JSONDecodeError as e:
                        problem(where, f"JSON does not parse: {e}: {line}")
        elif lang in ("sh", "bash") and marker == "run":
            scripts.append(text)
    if scripts and bindir:
        run_in_scratch(f"{rel(d.path)} (its `check: run` blocks)",
                       ["bash", "-euo", "pipefail", "-c", "\n".join(scripts)], bindir)


def run_in_scratch(where: str, argv: list[str], bindir: str | None) -> None:
    env = dict(os.environ)
    if bindir:
        env["PATH"] = bindir + os.pathsep + env.get("PATH", "")
    with tempfile.TemporaryDirectory(prefix="primo-docs-") as scratch:
        began = time.monotonic()
        try:
            run = subprocess.run(argv, cwd=scratch, env=env, capture_output=True, text=True, timeout=300)
        except subprocess.TimeoutExpired:
            problem(where, "did not finish within 300 s")
            return
        finally:
            runs.append((time.monotonic() - began, where))
        if run.returncode != 0:
            tail = "\n    ".join((run.stdout + run.stderr).strip().split("\n")[-15:])
            problem(where, f"failed (exit status {run.returncode}):\n    {tail}")


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--primo", required=True, help="the primo binary whose --help the commands are checked against")
    parser.add_argument("--python", help="a Python with the primo package installed: run the python blocks")
    args = parser.parse_args()
    primo = str(Path(args.primo).resolve())
    if not os.access(primo, os.X_OK):
        print(f"docs/check.py: no primo binary at {primo}", file=sys.stderr)
        return 1
    book = ROOT / "docs" / "src"
    files = [ROOT / f for f in ("README.md", "ARCHITECTURE.md", "CHANGELOG.md", "python/README.md")]
    files += sorted((ROOT / "bench" / "results").glob("*.md")) + sorted(book.rglob("*.md"))
    target = target_dir()
    help = Help(primo)
    for path in files:
        if not path.exists():
            problem(rel(path), "missing")
            continue
        d = doc(path)
        check_links(d, target)
        check_commands(d, help)
        check_blocks(d, args.python, str(Path(primo).parent))
    check_summary(book)
    for p in problems:
        print(p)
    if runs:
        slowest = ", ".join(f"{w} {t:.1f} s" for t, w in sorted(runs, reverse=True)[:3])
        print(f"docs/check.py: ran {len(runs)} blocks in {sum(t for t, _ in runs):.1f} s; slowest: {slowest}")
    print(f"docs/check.py: {len(files)} files, {sum(len(doc(f).links) for f in files if f.exists())} links, "
          f"{sum(len(doc(f).blocks) for f in files if f.exists())} code blocks: "
          + (f"{len(problems)} problem(s)" if problems else "all good"))
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
