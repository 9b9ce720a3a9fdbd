"""Every ``isaflow`` command line the docs show is one the command line accepts (isaflow.cli.parser).

A command line is taken from an inline code span or a fenced shell block of README.md, config/README.md and
docs/*.md; a line written as a synopsis (``[optional]``, ``a|b``, ``...``, ``{choices}``) is read with its
optional parts left out and its first choice taken.  A whole command line (one naming its output: ``-o`` or
``--vtk``) must parse; a fragment in prose (``isaflow run --threads 0``) must name only options that exist.
Parsing only: no run starts.
"""

import re
import shlex

import pytest

from isaflow import cli

from conftest import ROOT

DOCS = [ROOT / "README.md", ROOT / "config" / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
SPAN = re.compile(r"`(isaflow (?:run|export|compare)\b[^`]*)`")
FENCE = re.compile(r"```(?:bash|sh|console|shell)?\n(.*?)```", re.S)


def _commands(text):
    found = SPAN.findall(text)
    for block in FENCE.findall(text):
        found += [line.strip() for line in block.splitlines() if line.strip().startswith("isaflow ")]
    return found


def _concrete(line):
    """A synopsis as one concrete command line: comments, [optional] parts and '...' dropped, the first of a|b
    and of {a,b} taken, '(a | b)' groups read as their first alternative."""
    line = line.split(" #", 1)[0].strip()
    while re.search(r"\[[^\[\]]*\]", line):
        line = re.sub(r"\s*\[[^\[\]]*\]", "", line)
    line = re.sub(r"\(([^()|]*)\|[^()]*\)", r"\1", line)
    line = re.sub(r"\{([^,{}]*),[^{}]*\}", r"\1", line)
    line = re.sub(r"(\S+)\|\S+", r"\1", line)
    return line.replace("...", "").strip()


PARSER = cli.parser()
CASES = sorted({(path.relative_to(ROOT).as_posix(), cmd) for path in DOCS for cmd in _commands(path.read_text())})


def test_the_docs_show_command_lines_of_every_subcommand():
    assert {cmd.split()[1] for _, cmd in CASES} == {"run", "export", "compare"}


def _options(sub):
    """The option strings of subcommand sub."""
    action = next(a for a in PARSER._actions if a.dest == "cmd")
    return {o for a in action.choices[sub]._actions for o in a.option_strings}


@pytest.mark.parametrize("doc, command", CASES)
def test_a_documented_command_line_parses(doc, command, capsys):
    argv = shlex.split(_concrete(command))[1:]
    named = [a.split("=", 1)[0] for a in argv if a.startswith("-") and not re.fullmatch(r"-\d+(\.\d*)?", a)]
    assert set(named) <= _options(argv[0]), (doc, command, sorted(set(named) - _options(argv[0])))
    if not {"-o", "--out", "--vtk", "--help", "-h"} & set(named):  # a fragment in prose: its options exist
        return
    try:
        args = PARSER.parse_args(argv)
    except SystemExit as exc:
        if argv[-1] in ("--help", "-h") and exc.code == 0:
            return
        pytest.fail(f"{doc}: `{command}` is refused: {capsys.readouterr().err.strip()}")
    if args.cmd == "run":  # a run names its tank, rule and resolution, or a declared run
        assert args.run or (args.tank and args.variant and args.resolution), (doc, command)
