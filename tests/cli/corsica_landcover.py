"""Writes landcover.tif in the current folder: the land-cover raster of the plugin tests, in
Web Mercator, 250 m cells over the Cap Corse sample: forest (10) west of 9.2 E, grass (20) east of
it, wetland (80) over the reserve's box, 0 = no data outside."""
# SPDX-License-Identifier: MIT
from osgeo import gdal, osr
import numpy as np

srs = osr.SpatialReference(); srs.ImportFromEPSG(3857)
wgs84 = osr.SpatialReference(); wgs84.ImportFromEPSG(4326); wgs84.SetAxisMappingStrategy(osr.OAMS_TRADITIONAL_GIS_ORDER)
to, back = osr.CoordinateTransformation(wgs84, srs), osr.CoordinateTransformation(srs, wgs84)
x0, y0, _ = to.TransformPoint(8.6, 43.3); x1, y1, _ = to.TransformPoint(9.6, 42.4)
cols, rows = int((x1 - x0) / 250), int((y0 - y1) / 250)
ds = gdal.GetDriverByName("GTiff").Create("landcover.tif", cols, rows, 1, gdal.GDT_Byte)
ds.SetGeoTransform((x0, 250, 0, y0, 0, -250)); ds.SetProjection(srs.ExportToWkt())
codes = np.zeros((rows, cols), np.uint8)
for r in range(rows):
    for c in range(cols):
        lon, lat, _ = back.TransformPoint(x0 + (c + 0.5) * 250, y0 - (r + 0.5) * 250)
        codes[r, c] = 80 if (9.355 <= lon <= 9.385 and 42.675 <= lat <= 42.705) else 10 if lon < 9.2 else 20
ds.GetRasterBand(1).WriteArray(codes); ds.GetRasterBand(1).SetNoDataValue(0); ds = None
