#!/usr/bin/env python3
"""Reads a BCF archive with IfcOpenShell's `bcf` package (`pip install bcf-client`), an
independent BCF reader, and prints what it found as JSON:

    python3 bench/bcf_oracle.py FILE.bcfzip

{"version": "3.0", "topics": [{"guid", "title", "labels", "description", "type", "status",
  "viewpoints": [{"guid", "selected", "visible_exceptions", "default_visibility",
  "red", "camera": {"position", "direction", "up", "field_of_view"}, "snapshot": bool}]}]}
Exit code 1 when the reader refuses the file.
"""
import json
import sys

from bcf.bcfxml import load


def xyz(p):
    return [p.x, p.y, p.z]


def guids(components):
    return [c.ifc_guid for c in (components or [])]


def main():
    bcf = load(sys.argv[1])
    if bcf is None:
        print("the reader returned nothing", file=sys.stderr)
        sys.exit(1)
    version = bcf.version.version_id
    topics = []
    for guid, handler in sorted(bcf.topics.items()):
        t = handler.topic
        labels = t.labels.label if version == "3.0" and t.labels else (t.labels or [])
        views = []
        for name, vp in sorted(handler.viewpoints.items()):
            info = vp.visualization_info
            comps = info.components
            vis = comps.visibility
            red = []
            for color in (comps.coloring.color if comps.coloring else []):
                members = color.components.component if version == "3.0" else color.component
                if color.color.upper().endswith("FF0000"):
                    red += guids(members)
            cam = info.perspective_camera
            views.append({
                "guid": info.guid,
                "file": name,
                "selected": guids(comps.selection.component if comps.selection else []),
                "default_visibility": vis.default_visibility,
                "visible_exceptions": guids(vis.exceptions.component if vis.exceptions else []),
                "red": red,
                "camera": {
                    "position": xyz(cam.camera_view_point),
                    "direction": xyz(cam.camera_direction),
                    "up": xyz(cam.camera_up_vector),
                    "field_of_view": cam.field_of_view,
                },
                "snapshot": vp.snapshot is not None,
            })
        topics.append({
            "guid": guid,
            "title": t.title,
            "labels": list(labels),
            "description": t.description,
            "type": t.topic_type,
            "status": t.topic_status,
            "viewpoints": views,
        })
    json.dump({"version": version, "topics": topics}, sys.stdout, ensure_ascii=False, indent=1)
    print()


if __name__ == "__main__":
    main()
