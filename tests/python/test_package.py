"""The package imports from the build tree and exposes both halves of the library."""

import envmis


def test_the_package_imports_both_extension_modules():
    assert envmis._maps.__name__ == "envmis._maps"
    assert envmis._study.__name__ == "envmis._study"
