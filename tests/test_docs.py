"""The documentation cannot rot: its example output and figures come from the code."""
import os
import re

import pytest

from conftest import ROOT, in_process, run_cli


def test_readme_example_is_what_the_demo_prints(tmp_path):
    readme = open(os.path.join(ROOT, "README.md")).read()
    block = re.search(r"```\n(mu = 1 .*?)```", readme, re.S).group(1)
    proc = run_cli("-options_file", "options/demo.opts", "-out", tmp_path / "d.h5",
                   "-summary", tmp_path / "d.json", "-plot", tmp_path / "d.png")
    assert proc.returncode == 0, proc.stderr
    number = r"-?\d+\.\d{6,}"                     # the 8-digit event values, not times
    documented = re.findall(number, block)
    printed = re.findall(number, proc.stdout)
    assert len(documented) >= 10 and documented == printed
    assert (tmp_path / "d.png").stat().st_size > 10_000


@pytest.mark.parametrize("doc", ["results.md", "numerics.md", "model.md", "output.md"])
def test_figures_exist_and_name_their_command(doc):
    text = open(os.path.join(ROOT, "docs", doc)).read()
    for png in re.findall(r"\(figures/(\w+)\.png\)", text):
        assert os.path.exists(os.path.join(ROOT, "docs", "figures", f"{png}.png"))
        table = open(os.path.join(ROOT, "docs", "figures", f"{png}.md")).read()
        assert f"made by: ./run figures {png}" in table
        assert f"./run figures {png}" in text


def test_every_options_file_sets_up(tmp_path):
    """Each options file parses, its application options are known and in range, its
    output paths are writable (relative to results/, as ./run study makes it);
    -help stops after the set-up.  The program's main() in this process (conftest.in_process), file after file:
    27 processes of their own cost 1 CPU s each to start, the set-up itself a fiftieth of that."""
    (tmp_path / "results").mkdir()
    (tmp_path / "docs" / "figures").mkdir(parents=True)          # the paper figures' studies write there
    for name in sorted(os.listdir(os.path.join(ROOT, "options"))):
        proc = in_process("-options_file", os.path.join(ROOT, "options", name), "-help", cwd=tmp_path)
        assert proc.returncode == 0, (name, proc.stderr)


def test_usage_md_is_the_option_table():
    """docs/usage.md is what its command makes from the option table now, and lists every option
    once, in the group -help shows it in."""
    from petsc_adhesion.benchmarks import usage
    from petsc_adhesion.app.options.table import TABLE
    from petsc_adhesion.app.options.help import help_groups

    text = open(os.path.join(ROOT, "docs", "usage.md")).read()
    assert text == usage.markdown(), f"docs/usage.md is stale: regenerate it with {usage.COMMAND}"
    grouped = [o.name for _, members in help_groups() for o in members]
    assert sorted(grouped) == sorted(TABLE)
    for title, members in help_groups():
        section = text.split(f"## {title[0].upper()}{title[1:]}\n")[1].split("\n## ")[0]
        assert re.findall(r"^\| `-(\w+)` \|", section, re.M) == [o.name for o in members]


def test_architecture_md_names_every_module():
    """docs/architecture.md gives every module its one job: each file of the package is named there (by its
    path in its part, or its name in a part's list)."""
    text = open(os.path.join(ROOT, "docs", "architecture.md")).read()
    missing = []
    for folder, _, files in os.walk(os.path.join(ROOT, "petsc_adhesion")):
        for name in files:
            if not name.endswith(".py") or name == "__init__.py" and folder.endswith("petsc_adhesion"):
                continue
            rel = os.path.relpath(os.path.join(folder, name), os.path.join(ROOT, "petsc_adhesion"))
            parts = rel.split(os.sep)
            shown = {f"`{rel}`", f"`{'/'.join(parts[1:])}`", f"`{parts[-1]}`", f"`{parts[-2]}/`" if len(parts) > 1 else ""}
            if name == "__init__.py":
                shown |= {f"**`{parts[0]}/`**", f"`{parts[-2]}/`"}
            if not any(s and s in text for s in shown):
                missing.append(rel)
    assert not missing, missing


# -- the citation patterns and their examples (the one part of this file not searched for them) --
#: What cites a file or folder outside the repository: the notes and paths of the machine the project was built
#: on, a document of the team's beside the repository, a path climbing out of it, an issue number.
OUTSIDE = (r"\bNOTES\b", r"/work/", r"(?<![\w/.])/work\b", r"\.\./shared", r"\bpeers\.md\b", r"\bSTYLE\.md\b",
           r"\bscopes\.md\b", r"\bcommon\.md\b", r"\bprompts/", r"\bissue \d+", r"(?<![\w.])/home/\w",
           r"/root/")
#: Texts and whether they cite outside the repository.
EXAMPLES = [
    ("see peers.md for the band", True), ("STYLE.md says so", True), ("../shared/notes", True),
    ("/work/main/.venv/bin/python", True), ("cd /work && ls", True), ("/home/alice/x", True), ("issue 33", True),
    ("docs/performance.md", False), ("benchmarks/peers.py", False), ("/tmp/petsc-adhesion-check.XXXX", False),
    ("the work of adhesion", False), ("home/away", False)]
# -- end of the citation patterns --
#: The files of the repository that are read: the code, the tests, the docs, the options, the scripts.
CITING = ("petsc_adhesion", "tests", "docs", "options")
SCRIPTS = ("README.md", "run", "pyproject.toml")


def _outside(text: str) -> list:
    return [p for p in OUTSIDE if re.search(p, text)]


def test_nothing_cites_a_file_outside_the_repository():
    """The docs, the code and the tests (and README, ./run, pyproject.toml) cite the repository's own documents,
    never the notes or paths of the machine the project was built on, nor a document beside the repository
    (OUTSIDE).  This file is read too, but for its table of
    patterns and examples."""
    bad = []
    for top in CITING:
        for folder, _, files in os.walk(os.path.join(ROOT, top)):
            for name in files:
                if name.endswith((".py", ".md", ".opts", ".json", ".txt", ".csv")):
                    path = os.path.join(folder, name)
                    with open(path, encoding="utf-8", errors="replace") as f:
                        text = f.read()
                    if path == os.path.abspath(__file__):
                        start, end = "# -- the citation patterns", "# -- end of the citation patterns"
                        text = text[:text.index(start)] + text[text.index(end):]
                    bad += [f"{os.path.relpath(path, ROOT)}: {p}" for p in _outside(text)]
    for name in SCRIPTS:
        with open(os.path.join(ROOT, name), encoding="utf-8") as f:
            bad += [f"{name}: {p}" for p in _outside(f.read())]
    assert not bad, bad


@pytest.mark.parametrize("text, cites", EXAMPLES)
def test_the_outside_patterns_tell_citations_apart(text, cites):
    """The patterns find each kind of citation outside the repository and leave the repository's own names."""
    assert bool(_outside(text)) == cites, (text, _outside(text))
