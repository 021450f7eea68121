"""The one exception type of TopOpt's Python side."""


class TopOptError(RuntimeError):
    """Something the user can fix; str() says what, .code names the kind
    ("InvalidShape", "NonDesignOutside", "NoSupport", "FaceNotFound", ...)."""

    def __init__(self, message, code="Internal"):
        super().__init__(message)
        self.code = code
