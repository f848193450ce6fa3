# The README's Python script is tools/python_example.py, which ctest runs (python.example).
import re

from conftest import SRC


def test_readme_script_is_the_example_run_by_ctest():
    readme = (SRC / "README.md").read_text()
    section = readme[readme.index("\n## Python\n"):]
    block = re.search(r"```python\n(.*?)```", section, re.S).group(1)
    assert block == (SRC / "tools" / "python_example.py").read_text()
