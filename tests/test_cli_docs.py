"""One command line, as documented: every option the docs quote for a command exists in its
--help (a hidden old spelling does not count), every default the docs state is the one
--help states, --help states the defaults, and the fabric options read alike everywhere
(`--fabric NAME[,NAME..]` selects, `--fabrics DIR` is a folder, the old list a notice)."""

from __future__ import annotations

import argparse
import re
from pathlib import Path

import pytest

from catalog.commands.cli import build_parser, format_default, main
from catalog.core.resources import PROJECT_ROOT

DOCS = sorted((PROJECT_ROOT / "docs").glob("*.md")) + [PROJECT_ROOT / "README.md"]
_COMMAND = re.compile(r"(?:^|[\s`(])(?:python -m )?catalog ([a-z][a-z-]+)\b([^`]*)")
_OPTION = re.compile(r"(?<![\w-])(--[a-z][a-z0-9-]*)")
#: `--opt ...` then, before the next quoted option, "default X" / "default: X" / "default is X"
_CLAIM = re.compile(r"\bdefault(?:s to| is|:)?\s+`?([A-Za-z0-9_.:,x%+-]+)`?")


def _commands() -> dict[str, argparse.ArgumentParser]:
    return dict(build_parser()._subparsers._group_actions[0].choices)


def _visible_options(parser) -> dict[str, argparse.Action]:
    return {option: action for action in parser._actions for option in action.option_strings
            if action.help is not argparse.SUPPRESS}


def _help_default(action) -> str | None:
    default = action.default
    if default is None or default is False or default is argparse.SUPPRESS:
        return None
    return format_default(default)


def _doc_lines():
    """(path, line number, line, in_code): fenced blocks and indented code blocks (four
    spaces after a blank line) are code."""
    for path in DOCS:
        fenced = indented = False
        previous_blank = True
        for number, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1):
            if line.lstrip().startswith("```"):
                fenced = not fenced
                continue
            indented = line.startswith("    ") and (previous_blank or indented) and not fenced
            previous_blank = not line.strip()
            yield path, number, line, fenced or indented


def _quoted_command_lines():
    """(where, command, the text after it) for each `catalog CMD ...` in a code span or a
    code block."""
    for path, number, line, fenced in _doc_lines():
        spans = [line] if fenced else re.findall(r"`([^`]*)`", line)
        for span in spans:
            for match in _COMMAND.finditer(span):
                rest = match.group(2).split("#", 1)[0] if fenced else match.group(2)
                yield f"{path.relative_to(PROJECT_ROOT)}:{number}", match.group(1), rest


def test_every_option_the_docs_quote_is_in_the_commands_help():
    commands = _commands()
    wrong = []
    for where, command, rest in _quoted_command_lines():
        if command not in commands:
            continue  # a word after "catalog" in prose, or another tool's command
        options = _visible_options(commands[command])
        for option in _OPTION.findall(rest):
            if option not in options:
                wrong.append(f"{where}: catalog {command} {option}")
        for value in re.findall(r"--fabrics[ =]([^\s\]|`]+)", rest):
            if value != "DIR":  # a folder, never the second round's list
                wrong.append(f"{where}: catalog {command} --fabrics {value} (use --fabric)")
    assert not wrong, "\n".join(wrong)


def _quoted_options_with_their_command():
    """(where, command, option match, line) for each `--opt ...` quoted in prose. The
    command is the section's: the last `catalog CMD` of a heading or a code block above it
    (a usage line), else the first the file quotes; prose naming another command in passing
    does not change it."""
    commands = _commands()
    current, current_path = None, None
    for path, number, line, code in _doc_lines():
        if path != current_path:
            current, current_path = None, path
        mentions = [m.group(1) for m in _COMMAND.finditer(line) if m.group(1) in commands]
        if mentions and (code or line.startswith("#") or current is None):
            current = mentions[-1]
        if code or current is None:
            continue
        for match in re.finditer(r"`(--[a-z][a-z0-9-]*)([^`]*)`", line):
            yield f"{path.relative_to(PROJECT_ROOT)}:{number}", current, match, line


def test_every_default_the_docs_state_is_the_one_help_states():
    commands = _commands()
    wrong = []
    entries = list(_quoted_options_with_their_command())
    for i, (where, command, match, line) in enumerate(entries):
        options = _visible_options(commands[command])
        option = match.group(1)
        if option not in options:
            continue
        same_line_next = [m for w, _c, m, _l in entries[i + 1:i + 2] if w == where]
        end = same_line_next[0].start() if same_line_next else len(line)
        tail = line[match.end():end]
        stated = _help_default(options[option])
        claim = _CLAIM.search(tail)
        if re.match(r"\s*\(default\)", tail) and match.group(2).strip():
            claimed = match.group(2).strip()  # `--opt VALUE` (default)
        elif claim is not None:
            claimed = claim.group(1).rstrip(".,")
        else:
            continue
        help_text = options[option].help or ""
        if stated is None:
            if claimed.lower() not in help_text.lower():
                wrong.append(f"{where}: catalog {command} {option}: docs say default "
                             f"{claimed!r}, --help: {help_text!r}")
        elif not _same_value(claimed, options[option].default):
            wrong.append(f"{where}: catalog {command} {option}: docs say default "
                         f"{claimed!r}, --help says {stated!r}")
    assert not wrong, "\n".join(wrong)


def _same_value(text: str, default) -> bool:
    """``text`` names ``default``: the same words, or the same number (12 for 12.0, 1/60)."""
    text = text.strip().strip("'\"`").rstrip(".,:;").removeprefix("./")
    if text == format_default(default):
        return True
    try:
        number = float(default)
    except (TypeError, ValueError):
        return False
    try:
        a, _, b = text.partition("/")
        value = float(a) / float(b) if b else float(a)
    except ValueError:
        return False
    return abs(value - number) <= 1e-12 * max(1.0, abs(number))


def test_help_states_every_default():
    """Each option with a default shows it in --help: the formatter's ``(default: X)`` or the
    help's own words naming the same value."""
    missing = []
    for name, parser in _commands().items():
        for action in parser._actions:
            stated = _help_default(action)
            if stated is None or not action.option_strings or action.help is argparse.SUPPRESS:
                continue
            text = parser._get_formatter()._expand_help(action) if action.help else ""
            if "default" not in text.lower() or not any(
                    _same_value(word, action.default)
                    for word in re.split(r"[\s()]+", text)):
                missing.append(f"catalog {name} {action.option_strings[0]} ({stated}): {text!r}")
    assert not missing, "\n".join(missing)


LIST_COMMANDS = ("sheet", "render-catalog", "web")


@pytest.mark.parametrize("command", LIST_COMMANDS)
def test_fabric_selects_a_list_and_defaults_to_all(command, tmp_path):
    parser = _commands()[command]
    out = ["--out", str(tmp_path)]
    assert parser.parse_args(out).fabric is None  # left out: every fabric
    args = parser.parse_args([*out, "--fabric", "lace-fwa,voile-white", "--fabrics",
                              str(tmp_path), "--fabrics", str(PROJECT_ROOT / "fabrics")])
    assert args.fabric == ["lace-fwa", "voile-white"]
    assert args.fabrics == [tmp_path, PROJECT_ROOT / "fabrics"]
    assert "(default: all" in parser.format_help()


@pytest.mark.parametrize("command", LIST_COMMANDS)
def test_the_old_fabrics_list_is_still_accepted_with_one_notice(command, tmp_path, capsys):
    parser = _commands()[command]
    args = parser.parse_args(["--out", str(tmp_path / "o"),
                              "--fabrics", f"lace-fwa,{tmp_path},voile-white"])
    assert args.fabric == ["lace-fwa", "voile-white"] and args.fabrics == [tmp_path]
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "notice" in err[0] and "--fabric lace-fwa,voile-white" in err[0]


@pytest.mark.parametrize("command", ["snapshot", "view", "simulate", "reference", "sheet",
                                     "render-catalog", "web"])
def test_every_command_takes_fabric_and_a_fabrics_folder(command, tmp_path):
    options = _visible_options(_commands()[command])
    assert "--fabric" in options and "--fabrics" in options
    assert options["--fabrics"].metavar == "DIR"


def test_views_fabric_dir_is_an_alias_of_fabrics_with_a_notice(tmp_path, capsys):
    parser = _commands()["view"]
    assert "--fabric-dir" not in _visible_options(parser)
    args = parser.parse_args(["--fabric-dir", str(tmp_path)])
    assert args.fabrics == [tmp_path]
    assert "--fabric-dir is the old spelling of --fabrics DIR" in capsys.readouterr().err


def test_a_missing_fabrics_folder_is_refused_naming_the_option(tmp_path, capsys):
    status = main(["snapshot", "--fabric", "lace-fwa", "--fabrics", str(tmp_path / "none"),
                   "--out", str(tmp_path / "a.png")])
    err = capsys.readouterr().err.strip().splitlines()
    assert status == 2 and len(err) == 1 and "--fabrics" in err[0], err
    assert not (tmp_path / "a.png").exists()


def test_docs_files_are_read(tmp_path):
    """The checks above read something: the docs quote dozens of command lines."""
    assert sum(1 for _ in _quoted_command_lines()) > 40
    assert Path(PROJECT_ROOT / "docs" / "formats.md") in DOCS


def test_every_room_option_names_every_built_in_room():
    """--room reads alike in every command and lists the rooms the package ships (it said
    "box, living" in five commands after the bedroom was added)."""
    from catalog.room.load import BUILTIN_ROOMS

    rooms = [name for name, parser in _commands().items()
             if "--room" in _visible_options(parser) and name != "bench"]   # bench's: a filter
    assert {"snapshot", "view", "sheet", "reference", "render-catalog", "web", "export"} <= set(rooms)
    for name in rooms:
        action = _visible_options(_commands()[name])["--room"]
        assert action.metavar == "NAME|FILE.glb", name
        assert f"a built-in name ({', '.join(BUILTIN_ROOMS)})" in action.help, (name, action.help)
        assert f"default {action.default}" in action.help, name
