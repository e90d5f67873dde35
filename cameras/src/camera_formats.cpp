// The table of camera formats (camera_formats.h): a row per format, each defined in its own
// file; detection by content in the rows' priority order; the lists help and docs print.
#include "zcheck/camera_formats.h"

#include "formats.h"
#include "zcheck/camera_import.h"
#include "zcheck/error.h"

#include <algorithm>
#include <cctype>
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

namespace zcheck {

// The formats of this library, one row each, defined in its format's file. A new format: its
// file, and its row here.
namespace formats {
const CameraFormat& zcheckFormat();      // camera_file.cpp
const CameraFormat& colmapFormat();      // format_colmap.cpp
const CameraFormat& nerfstudioFormat();  // format_nerfstudio.cpp
const CameraFormat& opencvFormat();      // format_opencv.cpp
const CameraFormat& rosFormat();         // format_opencv.cpp
const CameraFormat& metashapeFormat();   // format_metashape.cpp
const CameraFormat& kalibrFormat();      // format_kalibr.cpp
}  // namespace formats

namespace {

std::vector<const CameraFormat*> builtInFormats()
{
    using namespace formats;
    return {&zcheckFormat(), &colmapFormat(), &nerfstudioFormat(), &opencvFormat(), &rosFormat(), &metashapeFormat(),
            &kalibrFormat()};
}

void sortByPriority(std::vector<const CameraFormat*>& rows)
{
    std::stable_sort(rows.begin(), rows.end(),
                     [](const CameraFormat* a, const CameraFormat* b) { return a->priority < b->priority; });
}

// Rows are added during static initialisation only (camera_formats.h), so the table needs no lock.
std::vector<const CameraFormat*>& rows()
{
    static auto* table = [] {
        return new std::vector<const CameraFormat*>(builtInFormats());  // never destroyed
    }();
    return *table;
}

// The first bytes of a file (at most `count`), for telling formats apart.
std::string headOf(const std::string& path, std::size_t count)
{
    checkInputFile(path, kCameraSetInput);
    const int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
    if (fd < 0) return "";
    std::string head(count, '\0');
    const ssize_t n = ::read(fd, head.data(), count);
    ::close(fd);
    head.resize(n > 0 ? std::size_t(n) : 0);
    return head;
}

std::string_view skipSpaceAndBom(std::string_view text)
{
    if (text.substr(0, 3) == "\xEF\xBB\xBF") text.remove_prefix(3);
    while (!text.empty() && std::isspace(static_cast<unsigned char>(text.front()))) text.remove_prefix(1);
    return text;
}

std::string namesOf(const CameraFormat& row)
{
    std::string out = row.name;
    for (const std::string& alias : row.aliases) out += " (" + alias + ")";
    return out;
}

bool selected(const CameraFormat& row, CameraFormatsWith which)
{
    switch (which) {
    case CameraFormatsWith::Reader: return true;
    case CameraFormatsWith::Writer: return row.write != nullptr;
    case CameraFormatsWith::Dataset: return row.datasetSource;
    }
    return false;
}

}  // namespace

bool CameraFileHead::looksLikeJson() const
{
    return (!head.empty() && (head.front() == '{' || head.front() == '[')) || lowerExtension(path) == ".json";
}

bool CameraFileHead::looksLikeXml() const { return !head.empty() && head.front() == '<'; }

bool CameraFileHead::has(std::string_view text) const { return head.find(text) != std::string_view::npos; }

bool CameraFileHead::hasKeyLine(std::string_view key) const
{
    for (std::size_t at = 0; (at = head.find(key, at)) != std::string_view::npos; at += key.size())
        if ((at == 0 || head[at - 1] == '\n') && head.substr(at + key.size(), 1) == ":") return true;
    return false;
}

const std::vector<const CameraFormat*>& cameraFormats() { return rows(); }

bool registerCameraFormat(const CameraFormat& format)
{
    for (const CameraFormat* row : rows())
        if (row->name == format.name) throw Error("camera format '" + format.name + "' is registered twice");
    rows().push_back(&format);
    return true;
}

const CameraFormat& cameraFormatNamed(const std::string& name)
{
    for (const CameraFormat* row : cameraFormats()) {
        if (row->name == name) return *row;
        if (std::find(row->aliases.begin(), row->aliases.end(), name) != row->aliases.end()) return *row;
    }
    throw Error("unknown camera format '" + name + "' (expected " + cameraFormatChoices(CameraFormatsWith::Reader, ", ") + ")");
}

const CameraFormat& detectCameraFormat(const std::string& path)
{
    struct stat status {};
    const bool isFolder = ::stat(path.c_str(), &status) == 0 && S_ISDIR(status.st_mode);
    // The head is enough: every writer puts the keys that tell formats apart near the start.
    const std::string head = isFolder ? std::string() : headOf(path, std::size_t(1) << 20);
    const CameraFileHead file{path, skipSpaceAndBom(head), isFolder};
    std::vector<const CameraFormat*> byPriority = cameraFormats();
    sortByPriority(byPriority);
    for (const CameraFormat* row : byPriority)
        if (row->detects(file)) return *row;
    if (isFolder)
        throw Error("'" + path + "' is a directory but not a COLMAP model: a model holds cameras.txt and images.txt, or "
                    "cameras.bin and images.bin");
    std::string titles;
    for (const CameraFormat* row : cameraFormats()) titles += (titles.empty() ? "" : ", ") + row->title;
    throw Error("camera file '" + path + "' is none of the camera formats zcheck reads (" + titles +
                "); name its format with --camera-format");
}

CameraSet readCameraSet(const std::string& path, const CameraFormat* format)
{
    const CameraFormat& row = format ? *format : detectCameraFormat(path);
    CameraSet set = row.parse ? row.parse(readInputFile(path, row.input), path) : row.read(path);
    set.path = path, set.format = row.name;
    return set;
}

std::string cameraFormatChoices(CameraFormatsWith which, const std::string& separator)
{
    std::string out;
    for (const CameraFormat* row : cameraFormats())
        if (selected(*row, which)) out += (out.empty() ? "" : separator) + namesOf(*row);
    return out;
}

std::string cameraFormatTable()
{
    std::string out = "| format | files | a frame | writes | dataset source |\n|---|---|---|---|---|\n";
    for (const CameraFormat* row : cameraFormats()) {
        std::string names = "`" + row->name + "`";
        for (const std::string& alias : row->aliases) names += ", `" + alias + "`";
        out += "| " + names + " | " + row->title + ": " + row->files + " | `" + row->example + "` | " +
               (row->write ? "yes" : "no") + " | " +
               (row->datasetSource ? (row->namesDepthMaps ? "yes" : "yes, with `--depth PATTERN`") : "no") + " |\n";
    }
    return out;
}

std::vector<CameraFileText> cameraInFormat(const Camera& camera, const CameraFormat& format, const std::string& name)
{
    if (!format.write)
        throw Error("cameras are written as " + cameraFormatChoices(CameraFormatsWith::Writer, ", ") + ", not " + format.name);
    return format.write(camera, name);
}

}  // namespace zcheck
