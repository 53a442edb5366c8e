"""A finished batch for CI: a JUnit XML report and GitHub Actions annotations.

Both read the summary (``run.write_summary``), one test case or annotation per
item, so a failed material shows up where CI shows failed tests, at its file
and line.
"""

from __future__ import annotations

import re
from typing import Any
from xml.etree import ElementTree

# XML 1.0 cannot hold most control characters, even escaped; a shader log might carry one.
NOT_XML = re.compile("[\x00-\x08\x0b\x0c\x0e-\x1f\ufffe\uffff]")


def one_line(text: str) -> str:
    return " ".join(text.split())


def junit_xml(summary: dict[str, Any]) -> bytes:
    """One ``testcase`` per item; a failed item carries ``<failure message=...>``."""
    items = summary["items"]
    counts = summary["counts"]
    attrs = {"name": "opaline batch", "tests": str(len(items)),
             "failures": str(counts.get("failed", 0)), "errors": "0",
             "skipped": str(counts.get("interrupted", 0)), "time": f"{summary['seconds']:.3f}"}
    root = ElementTree.Element("testsuites", attrs)
    suite = ElementTree.SubElement(root, "testsuite", attrs)
    for item in items:
        case = ElementTree.SubElement(suite, "testcase", {
            "classname": "opaline.batch", "name": item["name"],
            "time": f"{item['seconds']:.3f}", "file": item.get("file") or item["input"]})
        if item.get("line"):
            case.set("line", str(item["line"]))
        error = NOT_XML.sub("?", item.get("error") or "")
        if item["status"] == "failed":
            failure = ElementTree.SubElement(case, "failure", {"message": one_line(error),
                                                               "type": "failed"})
            failure.text = error
        elif item["status"] == "interrupted":
            ElementTree.SubElement(case, "skipped", {"message": "interrupted"})
        elif item["output"]:
            ElementTree.SubElement(case, "system-out").text = f"{item['status']}: {item['output']}"
    document: bytes = ElementTree.tostring(root, encoding="utf-8", xml_declaration=True)
    return document + b"\n"


def _escape(text: str, prop: bool = False) -> str:
    """GitHub's workflow-command escaping (``%``, CR, LF; also ``:`` and ``,`` in properties)."""
    text = text.replace("%", "%25").replace("\r", "%0D").replace("\n", "%0A")
    return text.replace(":", "%3A").replace(",", "%2C") if prop else text


def github_annotations(summary: dict[str, Any]) -> list[str]:
    """``::error file=F,line=N,title=...::message`` for each failed item."""
    lines = []
    for item in summary["items"]:
        if item["status"] != "failed":
            continue
        props = [f"file={_escape(item.get('file') or item['input'], True)}"]
        if item.get("line"):
            props.append(f"line={item['line']}")
        props.append(f"title={_escape('opaline batch: ' + item['name'], True)}")
        lines.append(f"::error {','.join(props)}::{_escape(item.get('error') or 'failed')}")
    return lines
