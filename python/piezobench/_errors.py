"""The exceptions piezobench raises (core/error.hpp)."""


class Error(Exception):
    """Base of piezobench's exceptions."""


class InputError(Error, ValueError):
    """The data, a file or an argument is wrong (the command line's exit code 3).

    Attributes:
        source:   the file or function the bad value came from ("" when unknown)
        field:    the argument, keyword, channel or file field that is wrong
        expected: what was expected
        found:    what was found
    (field, expected and found are empty for errors that do not fit that form)
    """

    source = ""
    field = ""
    expected = ""
    found = ""


class NumericalError(Error, ArithmeticError):
    """A method failed on valid input (the command line's exit code 4).

    Attributes:
        method:         the method that failed
        retry_may_help: True when other settings (order, tolerance, band, ...) may succeed
    """

    method = ""
    retry_may_help = False
