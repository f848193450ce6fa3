#pragma once
// Writes single-frame CT DICOM slices with GDCM's writer, for the DICOM tests and the
// fuzzing seed corpus: 16-bit signed stored values, a position, an orientation, a pixel
// spacing, a rescale and the series it belongs to.
#include <gdcmImageWriter.h>
#include <gdcmReader.h>
#include <gdcmTrace.h>
#include <gdcmWriter.h>

#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <glm/glm.hpp>
#include <stdexcept>
#include <string>
#include <vector>

namespace splat::test {

struct DicomSlice {
    int columns = 4, rows = 3;
    glm::dvec3 position{0.0};                    ///< ImagePositionPatient (LPS, mm)
    double orientation[6] = {1, 0, 0, 0, 1, 0};  ///< ImageOrientationPatient
    double pixelSpacing[2] = {0.5, 0.5};         ///< row spacing, column spacing
    double sliceThickness = 2.5;
    double slope = 1, intercept = 0;  ///< RescaleSlope / RescaleIntercept
    int instance = 1;                 ///< InstanceNumber
    int seriesNumber = 1;
    std::string seriesUid = "1.2.826.0.1.3680043.2.1125.1";
    std::string description = "test series";
    std::vector<std::int16_t> stored;  ///< columns * rows, row by row
};

inline void writeDicomSlice(const std::filesystem::path& path, const DicomSlice& s) {
    gdcm::Trace::WarningOff();
    gdcm::ImageWriter writer;
    gdcm::Image& image = writer.GetImage();
    image.SetNumberOfDimensions(2);
    image.SetDimension(0, unsigned(s.columns));
    image.SetDimension(1, unsigned(s.rows));
    image.SetPixelFormat(gdcm::PixelFormat(gdcm::PixelFormat::INT16));
    image.SetPhotometricInterpretation(gdcm::PhotometricInterpretation::MONOCHROME2);
    const double origin[3] = {s.position.x, s.position.y, s.position.z};
    image.SetOrigin(origin);
    image.SetDirectionCosines(s.orientation);
    // gdcm::Image spacing is (x = column spacing, y = row spacing, z).
    const double spacing[3] = {s.pixelSpacing[1], s.pixelSpacing[0], s.sliceThickness};
    image.SetSpacing(spacing);
    image.SetIntercept(s.intercept);
    image.SetSlope(s.slope);
    gdcm::DataElement pixels(gdcm::Tag(0x7fe0, 0x0010));
    pixels.SetByteValue(reinterpret_cast<const char*>(s.stored.data()),
                        std::uint32_t(s.stored.size() * sizeof(std::int16_t)));
    image.SetDataElement(pixels);

    gdcm::DataSet& ds = writer.GetFile().GetDataSet();
    auto put = [&](std::uint16_t g, std::uint16_t e, gdcm::VR vr, std::string value) {
        if (value.size() % 2) value += vr == gdcm::VR::UI ? '\0' : ' ';
        gdcm::DataElement de(gdcm::Tag(g, e));
        de.SetVR(vr);
        de.SetByteValue(value.data(), std::uint32_t(value.size()));
        ds.Replace(de);
    };
    put(0x0008, 0x0016, gdcm::VR::UI, "1.2.840.10008.5.1.4.1.1.2");  // CT Image Storage
    put(0x0008, 0x0060, gdcm::VR::CS, "CT");
    put(0x0008, 0x103e, gdcm::VR::LO, s.description);
    put(0x0020, 0x000e, gdcm::VR::UI, s.seriesUid);
    put(0x0020, 0x0011, gdcm::VR::IS, std::to_string(s.seriesNumber));
    put(0x0020, 0x0013, gdcm::VR::IS, std::to_string(s.instance));
    writer.SetFileName(path.string().c_str());
    if (!writer.Write()) throw std::runtime_error("cannot write DICOM test file " + path.string());

    // GDCM's image writer keeps only the first two origin coordinates of a 2D image (z is
    // written as 0), so ImagePositionPatient is set again on the written file.
    gdcm::Reader reader;
    reader.SetFileName(path.string().c_str());
    if (!reader.Read()) throw std::runtime_error("cannot reread DICOM test file " + path.string());
    char ipp[128];
    std::snprintf(ipp, sizeof ipp, "%.10g\\%.10g\\%.10g", s.position.x, s.position.y, s.position.z);
    std::string value = ipp;
    if (value.size() % 2) value += ' ';
    gdcm::DataElement de(gdcm::Tag(0x0020, 0x0032));
    de.SetVR(gdcm::VR::DS);
    de.SetByteValue(value.data(), std::uint32_t(value.size()));
    reader.GetFile().GetDataSet().Replace(de);
    gdcm::Writer rewrite;
    rewrite.SetFile(reader.GetFile());
    rewrite.SetFileName(path.string().c_str());
    if (!rewrite.Write()) throw std::runtime_error("cannot write DICOM test file " + path.string());
}

}  // namespace splat::test
