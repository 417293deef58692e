"""CL fixtures in the style of NX and SolidWorks CAM (cam.md section 9), shared by the tests.

Written here record by record (the published files they imitate may not be copied into the
project); the comments give the line numbers the tests refer to.
"""

NX_LISTING = [
    "",
    "Information listing created by\tcam_user",  # 2
    "Date\t01-Dec-2026 10:00:00",
    "Current work part\tC:\\parts\\bracket.prt",
    "Node name\tcam-station",
    "",
    "TOOL PATH/FACE_POCKET,TOOL,MILL_0.250",  # 7
    "TLDATA/MILL,0.2500,0.0000,2.0000,0.0000,0.0000",  # 8
    "MSYS/1.0000,2.0000,0.5000,0.0000000,1.0000000,0.0000000,-1.0000000,0.0000000,0.0000000",
    "$$ centerline data",  # 10
    "PAINT/PATH",  # 11
    "LOAD/TOOL,1,ADJUST,1",
    "PAINT/COLOR,186",
    "RAPID",
    "GOTO/0.0000,0.0000,1.0000,0.0000000,0.0000000,1.0000000",  # 15
    "RAPID",
    "GOTO/0.0000,0.0000,0.1000",
    "FEDRAT/IPM,10.0000",  # 18
    "GOTO/0.0000,0.0000,0.0000",  # 19: the first cut
    "GOTO/1.0000,0.0000,0.0000",
    "GOTO/1.0000,0.0000,0.0000",  # 21: repeats the tool position
    "GOTO/1.0000,1.0000,0.0000,0.6000000,0.0000000,0.8000000",  # 22
    "GOTO/0.0000,1.0000,0.0000",  # 23: keeps the axis of line 22
    "PAINT/COLOR,31",
    "RAPID",
    "GOTO/0.0000,1.0000,1.0000",
    "END-OF-PATH",
    "TOOL PATH/ARC_FINISH,TOOL,MILL_0.250",  # 28
    "TLDATA/MILL,0.2500,0.0000,2.0000,0.0000,0.0000",
    "MSYS/1.0000,2.0000,0.5000,0.0000000,1.0000000,0.0000000,-1.0000000,0.0000000,0.0000000",
    "RAPID",
    "GOTO/2.0000,0.0000,0.1000,0.0000000,0.0000000,1.0000000",
    "GOTO/2.0000,0.0000,0.0000",  # 33: the first cut of pass 2
    "CIRCLE/1.5000,0.0000,0.0000,0.0000000,0.0000000,1.0000000,0.5000,0.0060,0.5000,0.2500,0.0000",
    "GOTO/1.5000,0.5000,0.0000",  # 35: the arc's end
    "RAPID",
    "GOTO/3.0000,3.0000,1.0000",
    "GOTO/3.0000,3.0000,0.0000",  # 38: a pass of one point
    "END-OF-PATH",
    "Tool Path Listing has 33 lines.",  # 40: lines 7 to 39, as NX counts them
]


SOLIDWORKS = [
    "PARTNO/1",
    "UNIT/MM",
    "INSERT/[HOLDER=C40-M06EM2] 6MM CRB 2FL 19 LOC",  # 3
    "CUTTER/6.,0,3.,0,0,0,51.",
    "LOAD/TOOL,1",
    "CSI_SET_FLUTE_LENGTH/19.",  # 6
    "CSI_SET_EXTENSION_LENGTH/25.",
    "SELECT/TOOL,5",
    "COOLNT/FLOOD",
    "SPINDL/12000,RPM,CLW",  # 10
    "TRNTYP/WORLD,0,0,0",
    "CSYS/1.,0,0,10.,0,1.,0,20.,0,0,1.,-5.",
    "RAPID/",
    "GOTO/40.,0,25.",
    "RAPID/",
    "GOTO/40.,0,2.5",
    "FEDRAT/400.,MMPM",
    "GOTO/40.,0,-3.",  # 18: the first cut
    "FEDRAT/1600.,MMPM",
    "CUTCOM/LEFT",  # 20
    "GOTO/40.,30.,-3.",
    "CIRCLE/30.,30.,-3.,0,0,1.",  # 22: no radius, the shorter way (a quarter, ccw)
    "GOTO/30.,40.,-3.",
    "GOTO/0,40.,-3.",  # 24
    "CIRCLE/0,20.,-3.,0,0,-1.",  # 25: a full circle, ccw about -z
    "GOTO/0,40.,-3.",
    "CUTCOM/OFF",
    "RAPID/",
    "GOTO/0,40.,25.",
    "FINI",  # 30
]


def text(lines: list[str]) -> str:
    """A fixture as a file."""
    return "\n".join(lines) + "\n"
