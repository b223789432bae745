// The files of a comparison: opening, root attributes as text, tables and columns.
#include "compare_input.hpp"

#include <algorithm>
#include <cstdio>

#include "h5_checks.hpp"
#include "table_layout.hpp"

namespace graspsim::recordings::compare {
namespace {

herr_t collect_attribute(hid_t, const char* name, const H5A_info_t*, void* out) {
  static_cast<std::vector<std::string>*>(out)->push_back(name);
  return 0;
}

herr_t collect_link(hid_t, const char* name, const H5L_info_t*, void* out) {
  static_cast<std::vector<std::string>*>(out)->push_back(name);
  return 0;
}

std::string format_double(double x) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.17g", x);
  return buf;
}

bool is_table_dataset(hid_t loc, const std::string& path, const std::string& context) {
  h5::Handle d = h5::checked(H5Dopen2(loc, path.c_str(), H5P_DEFAULT), H5Dclose,
                             context + ": cannot open " + quoted(path));
  return h5::is_table(d.get(), context);
}

}  // namespace

OpenTrace open_trace(const std::string& path) {
  h5::OpenFile opened = h5::open_read_only(path, "cannot open trace " + quoted(path));
  OpenTrace trace;
  trace.name = path;
  trace.file = std::move(opened.file);
  trace.swmr = opened.swmr;   // skipped the still-open mark, as h5py's swmr=True does
  return trace;
}

// Any root attribute as text: strings as they are, numbers exactly (%.17g), arrays joined by
// ", ", anything else by its type.
std::string attribute_text(hid_t object, const std::string& name, const std::string& context) {
  h5::Handle attribute = h5::checked(H5Aopen(object, name.c_str(), H5P_DEFAULT), H5Aclose,
                                     context + ": cannot open attribute " + quoted(name));
  h5::Handle type = h5::checked(H5Aget_type(attribute.get()), H5Tclose, context);
  h5::Handle space = h5::checked(H5Aget_space(attribute.get()), H5Sclose, context);
  const hssize_t n = H5Sget_simple_extent_npoints(space.get());
  const H5T_class_t type_class = H5Tget_class(type.get());
  // A damaged dataspace may claim any count: 8 bytes each must fit in the file.
  if (n < 0 || static_cast<std::uint64_t>(n) > h5::file_size(object, context) / 8)
    fail(context + ": attribute " + quoted(name) + " claims " + std::to_string(n) + " elements (damaged?)");
  if (type_class == H5T_STRING && n == 1) return h5::read_string_attribute(object, name, context);
  if ((type_class == H5T_INTEGER || type_class == H5T_FLOAT) && n >= 1) {
    std::string text;
    if (type_class == H5T_INTEGER && H5Tget_sign(type.get()) == H5T_SGN_NONE) {
      std::vector<unsigned long long> v(static_cast<std::size_t>(n));
      h5::check(H5Aread(attribute.get(), H5T_NATIVE_ULLONG, v.data()), context);
      for (std::size_t i = 0; i < v.size(); ++i) text += (i ? ", " : "") + std::to_string(v[i]);
    } else if (type_class == H5T_INTEGER) {
      std::vector<long long> v(static_cast<std::size_t>(n));
      h5::check(H5Aread(attribute.get(), H5T_NATIVE_LLONG, v.data()), context);
      for (std::size_t i = 0; i < v.size(); ++i) text += (i ? ", " : "") + std::to_string(v[i]);
    } else {
      std::vector<double> v(static_cast<std::size_t>(n));
      h5::check(H5Aread(attribute.get(), H5T_NATIVE_DOUBLE, v.data()), context);
      for (std::size_t i = 0; i < v.size(); ++i) text += (i ? ", " : "") + format_double(v[i]);
    }
    return text;
  }
  return "<attribute of HDF5 class " + std::to_string(static_cast<int>(type_class)) + ", " +
         std::to_string(n) + " elements>";
}

std::map<std::string, std::string> root_attributes(const OpenTrace& t) {
  const std::string context = "trace " + quoted(t.name);
  std::vector<std::string> names;
  hsize_t index = 0;
  h5::check(H5Aiterate2(t.file.get(), H5_INDEX_NAME, H5_ITER_INC, &index, collect_attribute,
                        &names),
            context + ": cannot list the root attributes");
  std::map<std::string, std::string> out;
  for (const std::string& name : names) out[name] = attribute_text(t.file.get(), name, context);
  return out;
}

std::int64_t int_attribute(const OpenTrace& t, const std::string& name) {
  return h5::read_int_attribute(t.file.get(), name, "trace " + quoted(t.name));
}

H5I_type_t object_type(hid_t loc, const std::string& path, const std::string& context) {
  h5::Handle object = h5::checked(H5Oopen(loc, path.c_str(), H5P_DEFAULT), H5Oclose,
                                  context + ": cannot open " + quoted(path));
  return H5Iget_type(object.get());
}

// Tables at the top of the file, by name: compound datasets (schema 3 and 4: one dataset per loop,
// its columns in its rows) or groups of datasets (schema 2 and before).
std::vector<std::string> top_groups(const OpenTrace& t) {
  const std::string context = "trace " + quoted(t.name);
  std::vector<std::string> links, groups;
  hsize_t index = 0;
  h5::check(H5Literate(t.file.get(), H5_INDEX_NAME, H5_ITER_INC, &index, collect_link, &links),
            context + ": cannot list the root group");
  for (const std::string& l : links) {
    const H5I_type_t type = object_type(t.file.get(), l, context);
    if (type == H5I_DATASET && is_table_dataset(t.file.get(), l, context)) groups.push_back(l);
    if (type != H5I_GROUP) continue;
    // A group of tables (/devices/<finger>) is compared table by table; any other
    // group (a schema 2 loop: one dataset per column) as one table.
    std::vector<std::string> children, tables;
    h5::Handle g = h5::checked(H5Gopen2(t.file.get(), l.c_str(), H5P_DEFAULT), H5Gclose,
                               context + ": cannot open group " + quoted("/" + l));
    hsize_t child_index = 0;
    h5::check(H5Literate(g.get(), H5_INDEX_NAME, H5_ITER_INC, &child_index, collect_link, &children),
              context + ": cannot list group " + quoted("/" + l));
    for (const std::string& c : children)
      if (object_type(g.get(), c, context) == H5I_DATASET && is_table_dataset(g.get(), c, context))
        tables.push_back(l + "/" + c);
    if (tables.empty()) groups.push_back(l);
    else groups.insert(groups.end(), tables.begin(), tables.end());
  }
  return groups;
}

// Every column of table `group`, by name: the columns of a compound table (table_layout.hpp), or the datasets
// below a group (recursively), as paths relative to it.
std::vector<std::string> datasets_below(const OpenTrace& t, const std::string& group) {
  const std::string context = "trace " + quoted(t.name);
  std::vector<std::string> out;
  if (object_type(t.file.get(), group, context) == H5I_DATASET) {
    h5::Handle d = h5::checked(H5Dopen2(t.file.get(), group.c_str(), H5P_DEFAULT), H5Dclose,
                               context + ": cannot open " + quoted("/" + group));
    return h5::table_layout(d.get(), context + ", table " + quoted("/" + group)).sorted_names();
  }
  h5::Handle g = h5::checked(H5Gopen2(t.file.get(), group.c_str(), H5P_DEFAULT), H5Gclose,
                             context + ": cannot open group " + quoted("/" + group));
  std::vector<std::string> links;
  h5::check(H5Lvisit(g.get(), H5_INDEX_NAME, H5_ITER_INC, collect_link, &links),
            context + ": cannot list group " + quoted("/" + group));
  for (const std::string& l : links)
    if (object_type(g.get(), l, context) == H5I_DATASET) out.push_back(l);
  std::sort(out.begin(), out.end());
  return out;
}

}  // namespace graspsim::recordings::compare
