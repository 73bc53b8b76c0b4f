"""docs/world-json.md names every field of the shipped JSON Schema, and nothing the schema lacks."""

from __future__ import annotations

import json
import re
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]


def schema_fields() -> set[str]:
    schema = json.loads((REPO / "worldgen" / "schema" / "world.schema.json").read_text())
    defs = schema.get("$defs", {})
    out: set[str] = set()

    def walk(node: dict, path: str, depth: int = 0) -> None:
        if "$ref" in node:
            if depth < 8:
                walk(defs[node["$ref"].split("/")[-1]], path, depth + 1)
            return
        for name, sub in node.get("properties", {}).items():
            here = f"{path}.{name}" if path else name
            out.add(here)
            walk(sub, here, depth + 1)
        if node.get("type") == "array" and "items" in node:
            walk(node["items"], path + "[]", depth + 1)
        for key in ("oneOf", "anyOf", "allOf"):
            for alt in node.get(key, []):
                walk(alt, path, depth + 1)

    walk(schema, "")
    return out


def test_world_json_doc_lists_exactly_the_schema_fields():
    text = (REPO / "docs" / "world-json.md").read_text()
    documented = set(re.findall(r"^\| `([^`]+)` \|", text, flags=re.M))
    fields = schema_fields()
    assert fields - documented == set(), "fields the doc does not describe"
    assert documented - fields == set(), "fields the doc describes that the schema does not have"


def test_the_code_cites_documents_that_exist():
    """A docstring or comment that names a .md document names one the repository has."""
    sources = sorted((REPO / "worldgen").rglob("*.py")) + sorted((REPO / "tests").rglob("*.py"))
    for path in (p for p in sources if p.name != "test_docs.py"):  # this file names a missing one on purpose
        # A document is cited as docs/NAME.md, by a relative path, or by an upper-case name (METADATA.md);
        # report.md and the like are files worldgen writes, not citations.
        for cited in re.findall(r"((?:\.\./|docs/)[\w./-]+\.md|\b[A-Z][A-Z_]+\.md)\b", path.read_text()):
            assert (REPO / cited).exists() or (REPO / "docs" / cited).exists(), \
                f"{path.relative_to(REPO)} cites {cited}, which the repository does not have"


def test_readme_points_at_documents_that_exist():
    readme = (REPO / "README.md").read_text()
    assert "METADATA.md" not in readme
    for target in re.findall(r"\]\(((?:docs|examples)/[^)#]+)\)", readme):
        assert (REPO / target).exists(), target


def test_readme_is_a_tour_and_every_reference_page_is_linked():
    readme = (REPO / "README.md").read_text()
    assert len(readme.splitlines()) <= 200, "the README is a tour; the reference lives in docs/"
    assert "make demo" in readme and "make test" in readme
    linked = set(re.findall(r"\]\(docs/([^)#]+)\)", readme))
    assert linked == {p.name for p in (REPO / "docs").glob("*.md")}, "every docs page is linked from the README"


@pytest.mark.parametrize("page", sorted(p.name for p in (REPO / "docs").glob("*.md")))
def test_links_between_docs_pages_resolve(page):
    text = (REPO / "docs" / page).read_text()
    for target in re.findall(r"\]\(([^)#:]+)(?:#[^)]*)?\)", text):
        assert (REPO / "docs" / target).resolve().exists(), f"{page} links to {target}"


def test_generators_doc_holds_every_parameter_as_worldgen_list_prints_it():
    from worldgen.cli.world import parameter_tables
    from worldgen.generators import all_specs

    text = (REPO / "docs" / "generators.md").read_text()
    block = re.search(r"<!-- begin: worldgen list --markdown -->\n(.*)<!-- end: worldgen list --markdown -->", text, re.S)
    assert block, "docs/generators.md lost its parameter tables"
    assert block.group(1) == parameter_tables(all_specs()), "run `worldgen list --markdown` and paste it into docs/generators.md"


def test_the_docs_name_test_files_that_exist():
    """A page that says which test checks a claim names a file the suite has (tests moved into folders)."""
    for page in sorted((REPO / "docs").glob("*.md")) + [REPO / "README.md"]:
        for named in re.findall(r"\btests/[\w/]+\.py\b", page.read_text()):
            assert (REPO / named).exists(), f"{page.name} names {named}, which the suite does not have"
