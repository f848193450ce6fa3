# The Python document's script is tools/python_example.py, which ctest runs (python.example);
# this keeps the copy in splat/docs/python.md identical to the file that is run.
import re

from conftest import SRC


def test_python_doc_script_is_the_example_run_by_ctest():
    doc = (SRC / "splat" / "docs" / "python.md").read_text()
    block = re.search(r"```python\n(.*?)```", doc, re.S).group(1)
    assert block == (SRC / "tools" / "python_example.py").read_text()
