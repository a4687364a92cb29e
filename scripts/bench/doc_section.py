"""A generated section of a Markdown file, between its begin and end markers."""
import os


def splice(path, section, begin, end, empty=""):
    """Replaces the text from `begin` to `end` (markers included) in the file at path with
    `section`, or appends `section` when the markers are not both there. A missing file starts
    as `empty`."""
    text = open(path).read() if os.path.exists(path) else empty
    if begin in text and end in text:
        text = text[:text.index(begin)] + section + text[text.index(end) + len(end):]
    else:
        text = text.rstrip("\n") + "\n\n" + section + "\n"
    with open(path, "w") as f:
        f.write(text)
