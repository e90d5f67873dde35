// The table of depth-map formats (depth_map_formats.h) and the one dispatch over it: one
// sniffing rule for reading (the first bytes), one for writing (the extension).
#include "zcheck/depth_map_formats.h"

#include "depth_formats.h"
#include "zcheck/error.h"
#include "zcheck/input_file.h"

#include <algorithm>
#include <fstream>
#include <mutex>

namespace zcheck {

namespace {

struct Table {
    std::mutex mutex;         // the rows and the loader
    std::mutex loadingMutex;  // held while the loader runs: other readers wait for its formats
    std::vector<const DepthMapFormat*> rows;
    std::function<void()> loader;
    bool loaded = false;
};

// This library's formats, one row each, defined in its format's file.
Table& table()
{
    static auto* made = [] {
        auto* t = new Table;  // never destroyed: maps may be read during static destruction
        using namespace depthformats;
        t->rows = {&npyFormat(), &hdf5Format(), &colmapDepthFormat(), &pfmFormat(), &png16Format()};
        return t;
    }();
    return *made;
}

// Runs the loader once (it may register more formats), or waits for the thread running it;
// false when there is no loader, so that the table cannot grow.
bool loadMore()
{
    Table& t = table();
    const std::lock_guard<std::mutex> loading(t.loadingMutex);
    std::function<void()> loader;
    {
        const std::lock_guard<std::mutex> lock(t.mutex);
        if (!t.loader) return false;
        if (t.loaded) return true;
        t.loaded = true;
        loader = t.loader;
    }
    loader();
    return true;
}

const DepthMapFormat* formatOfHead(std::string_view head)
{
    for (const DepthMapFormat* format : depthMapFormats())
        if (format->detects(head)) return format;
    return nullptr;
}

const DepthMapFormat* formatOfExtension(const std::string& extension)
{
    for (const DepthMapFormat* format : depthMapFormats())
        if (format->write && std::count(format->extensions.begin(), format->extensions.end(), extension)) return format;
    return nullptr;
}

// "A, B or C" of the formats' titles (or of their written extensions).
std::string listed(bool extensions)
{
    std::vector<std::string> items;
    for (const DepthMapFormat* format : depthMapFormats()) {
        if (!extensions) items.push_back(format->title);
        else if (format->write)
            for (const std::string& extension : format->extensions) items.push_back(extension);
    }
    std::string out;
    for (std::size_t i = 0; i < items.size(); ++i) out += (i == 0 ? "" : i + 1 == items.size() ? " or " : ", ") + items[i];
    return out;
}

}  // namespace

std::vector<const DepthMapFormat*> depthMapFormats()
{
    Table& t = table();
    const std::lock_guard<std::mutex> lock(t.mutex);
    return t.rows;
}

bool registerDepthMapFormat(const DepthMapFormat& format)
{
    Table& t = table();
    const std::lock_guard<std::mutex> lock(t.mutex);
    for (const DepthMapFormat* row : t.rows)
        if (row->name == format.name) return true;
    t.rows.push_back(&format);
    return true;
}

void setDepthMapFormatLoader(std::function<void()> loader)
{
    Table& t = table();
    const std::lock_guard<std::mutex> lock(t.mutex);
    t.loader = std::move(loader);
    t.loaded = false;
}

DepthMapFile readDepthMapFile(const std::string& path, const DepthMapReading& reading, int expectedWidth, int expectedHeight)
{
    if (reading.scale != 0) DepthMapReading::requireScale(reading.scale, "--scale");
    if (reading.offset) DepthMapReading::requireOffset(*reading.offset, "--offset");
    checkInputFile(path, kDepthMapInput);
    char head[kDepthMapHeadBytes] = {};
    std::streamsize headBytes = 0;
    {
        std::ifstream probe(path, std::ios::binary);
        probe.read(head, sizeof head);
        headBytes = probe.gcount();
    }
    const std::string_view first(head, std::size_t(headBytes));
    const DepthMapFormat* format = formatOfHead(first);
    if (!format && loadMore()) format = formatOfHead(first);
    if (!format) refuseDepthMap(path, "not a " + listed(false) + " file (judged by its first bytes)");
    return format->read(path, reading, expectedWidth, expectedHeight);
}

std::string writeDepthMapFile(const std::string& path, const std::vector<QuantityImage>& images, double scale)
{
    const std::string extension = lowerExtension(path);
    const DepthMapFormat* format = formatOfExtension(extension);
    if (!format && loadMore()) format = formatOfExtension(extension);
    if (!format) throw Error("cannot write '" + path + "': unknown format '" + extension + "' (expected " + listed(true) + ")");
    if (images.empty()) throw Error("nothing to write to '" + path + "'");
    if (images.size() > 1 && !format->writesSeveral) {
        loadMore();  // the formats that take several may not be registered yet
        std::vector<std::string> extensions;
        for (const DepthMapFormat* row : depthMapFormats())
            if (row->writesSeveral) extensions.push_back(row->extensions.front());
        std::sort(extensions.begin(), extensions.end());
        std::string several;
        for (const std::string& extension : extensions) several += (several.empty() ? "" : " or ") + extension;
        throw Error("cannot write '" + path + "': several quantities go into one file only as " + several);
    }
    format->write(path, images, scale);
    return format->name;
}

void loadAllDepthMapFormats() { loadMore(); }

std::string depthMapFormatTable()
{
    loadMore();
    std::string out = "| depth map | read when its first bytes are | written as (by extension) |\n|---|---|---|\n";
    for (const DepthMapFormat* format : depthMapFormats()) {
        std::string extensions;
        for (const std::string& extension : format->extensions) extensions += (extensions.empty() ? "`" : ", `") + extension + "`";
        out += "| `" + format->name + "` | " + format->title + " | " +
               (format->write ? extensions + ": " + format->holds : "not written") + " |\n";
    }
    return out;
}

}  // namespace zcheck
