"""The fenced code blocks of a Markdown page, for the tests that run a document's examples
(json_api_doc_test.py, test/gateway/deployment_doc_test.py)."""
import re

FENCE = re.compile(r"^```(\w*)\s*$")


def blocks(text):
    """(info string, lines, line number of the opening fence) of every fenced block, in page order."""
    out, cur, info, start = [], None, None, 0
    for n, line in enumerate(text.splitlines(), 1):
        m = FENCE.match(line)
        if cur is None and m:
            cur, info, start = [], m.group(1), n
        elif cur is not None and line.strip() == "```":
            out.append((info, cur, start))
            cur = None
        elif cur is not None:
            cur.append(line)
    return out
