"""UPD-24's loads for the system tests: the centrifugal damper load CF [N] and the blade
excitation F0 [N] of ``damper upd frf --cf 120 --f0 30``.

A module of its own (not conftest): a test file importing names from ``conftest`` gets
whichever conftest was imported first when several test folders are collected together.
"""
CF, F0 = 120.0, 30.0
