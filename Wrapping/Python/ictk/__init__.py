"""ICTK, the Implicit Complex ToolKit: VTK algorithms for heterogeneous FRep objects.

    import vtk
    from ictk import ictkFiltersFRep
    sampler = ictkFiltersFRep.ictkFRepSampler()
    sampler.SetModelName("walnut")
    sampler.SetSampleDimensions(64, 64, 64)
    sampler.Update()
"""
